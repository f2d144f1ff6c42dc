// The one place every subcommand opens a camera from a spec string (INTERFACES.md section 1).
//
//   camera:N, video:PATH, images:DIR   -> vision::open_source (core/vision)
//   recipe:PATH[?live=1]               -> a fixture recipe rendered on the fly through the
//                                         MuJoCo hand model (sim/fixtures, OSMesa); live=1
//                                         loops it at its frame rate like a camera
//   tello:[ADDRESS][?...], tello-video:  a Tello's own camera: streamon, H.264 on UDP 11111
//                                         (adapters/tello_video; docs/ADAPTERS.md)
//
// Throws vision::CaptureError naming the source and the fix when it cannot be opened.
#pragma once

#include <memory>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/capture.hpp"

namespace gbdcs::app {

// The clock must outlive the source.
std::unique_ptr<vision::CaptureSource> open_any_source(std::string_view spec,
                                                       const contracts::Clock& clock);

// True when `spec` names a source by scheme (camera:, video:, images:, recipe:, tello:) rather than
// being a plain file path.
bool is_source_spec(std::string_view spec);

}  // namespace gbdcs::app
