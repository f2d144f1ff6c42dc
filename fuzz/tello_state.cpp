// The Tello state datagram (UDP 8890), as TelloAdapter receives it.
//
// Checks: parse_state_pairs and decode_state return a value or nullopt with a reason; a
// decoded state has its three required fields among the pairs, with finite numbers.
#include <cmath>

#include "fuzz_harness.hpp"
#include "gbdcs/adapters/tello_state.hpp"

namespace gbdcs::fuzz {
namespace {
constexpr std::string_view kName = "tello_state";
}

void tello_state(Bytes input) {
  const auto datagram = as_text(input);
  std::string why;
  const auto pairs = adapters::parse_state_pairs(datagram, why);
  require(pairs.has_value() || !why.empty(), kName, "rejected pairs without a reason");
  why.clear();
  const auto state = adapters::decode_state(datagram, why);
  if (!state) {
    require(!why.empty(), kName, "rejected a datagram without a reason");
    return;
  }
  require(pairs.has_value(), kName, "decode_state accepted what parse_state_pairs rejected");
  for (const char* key : {"h", "bat", "yaw"}) {
    require(state->fields.count(key) == 1, kName, std::string("accepted without ") + key);
  }
  require(std::isfinite(state->h_cm) && std::isfinite(state->bat_pct) &&
              std::isfinite(state->yaw_deg),
          kName, "a required field decoded to a non-finite number: " + std::string(datagram));
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(tello_state)
