#include "source_factory.hpp"

#include <array>
#include <string>

#include "fixture_support.hpp"
#include "gbdcs/adapters/tello_video_source.hpp"

namespace gbdcs::app {

bool is_source_spec(std::string_view spec) {
  constexpr std::array<std::string_view, 6> kSchemes = {"camera:", "video:",      "images:",
                                                        "recipe:", "tello:", "tello-video:"};
  for (auto scheme : kSchemes) {
    if (spec.substr(0, scheme.size()) == scheme) return true;
  }
  return false;
}

std::unique_ptr<vision::CaptureSource> open_any_source(std::string_view spec,
                                                       const contracts::Clock& clock) {
  if (spec.substr(0, 7) == "recipe:") return open_recipe_source(spec, clock);
  if (adapters::is_tello_video_spec(spec)) return adapters::open_tello_video(spec, clock);
  return vision::open_source(spec, clock);
}

}  // namespace gbdcs::app
