// The list of harnesses, for the regression test (not part of the libFuzzer binaries).
#include "fuzz_harness.hpp"

namespace gbdcs::fuzz {

const std::vector<Harness>& harnesses() {
  static const std::vector<Harness> all = {
      {"json_messages", json_messages},     {"rest_request", rest_request},
      {"tello_state", tello_state},         {"airsim_rpc", airsim_rpc},
      {"tflite_model", tflite_model},       {"scenario_loader", scenario_loader},
      {"fixture_recipe", fixture_recipe},
  };
  return all;
}

}  // namespace gbdcs::fuzz
