// What `gbdcs vision` adds for the server (INTERFACES.md sections 1 and 2):
//   picture_message    the live feed's `picture` message (vision_picture schema) for a
//                      captured frame: downscaled to `width_px`, JPEG, base64 (--publish-jpeg;
//                      sent at the camera's rate by a vision::FeedTap, apart from tracking)
//   run_timeline_worker  `--source timeline:PATH[?hold=1]`: a sim/timeline GestureTimeline
//                      played in real time as frame messages (landmarks, per-frame gesture,
//                      no pixels) plus heartbeats; after the timeline, frames without a hand
//                      until interrupted (a camera with nobody in front of it).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/vision/frame.hpp"

namespace gbdcs::app {

nlohmann::json picture_message(const vision::Frame& frame, int width_px, int quality);

using Emit = std::function<void(const nlohmann::json&)>;
int run_timeline_worker(const std::string& spec, double heartbeat_s, const Emit& emit,
                        const std::atomic<bool>& interrupted);

}  // namespace gbdcs::app
