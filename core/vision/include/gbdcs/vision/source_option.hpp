// Options in a capture source's query string (video:PATH?live=1&fps=30, recipe:PATH?...).
#pragma once

#include <optional>
#include <string_view>

namespace gbdcs::vision {

// The number in `option` when it reads "<name>=<number>" with nothing after the number;
// nullopt when the option has another name or the value is not a number. Each source checks
// the range it accepts and names it in its own error.
std::optional<double> number_option(std::string_view option, std::string_view name);

}  // namespace gbdcs::vision
