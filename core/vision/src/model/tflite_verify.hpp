// Where a flatbuffer that failed verification goes wrong, for an error message a person can
// act on ("subgraphs[0].tensors[57] (table at offset 1234) is truncated or corrupt").
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace gbdcs::vision::detail {

// Full verification of a TFLite Model buffer with our schema (identifier "TFL3").
bool verify_model_buffer(std::span<const std::uint8_t> bytes);

// Only called after verify_model_buffer() failed: the first part found bad, as text.
std::string describe_verification_failure(std::span<const std::uint8_t> bytes);

}  // namespace gbdcs::vision::detail
