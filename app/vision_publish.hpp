// What `gbdcs vision` adds for the server (INTERFACES.md sections 1 and 2):
//   JpegTap            a CaptureSource decorator keeping a downscaled base64 JPEG of each of
//                      the last frames, so the frame message can carry it (--publish-jpeg)
//   run_timeline_worker  `--source timeline:PATH[?hold=1]`: a sim/timeline GestureTimeline
//                      played in real time as frame messages (landmarks, per-frame gesture,
//                      no pixels) plus heartbeats; after the timeline, frames without a hand
//                      until interrupted (a camera with nobody in front of it).
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "gbdcs/vision/capture.hpp"

namespace gbdcs::app {

class JpegTap final : public vision::CaptureSource {
 public:
  JpegTap(std::unique_ptr<vision::CaptureSource> inner, int width_px, int quality);
  std::optional<vision::Frame> next() override;
  bool live() const override { return inner_->live(); }
  std::string describe() const override { return inner_->describe(); }
  std::optional<std::string> take(std::int64_t frame_id);  // base64 JPEG

 private:
  std::unique_ptr<vision::CaptureSource> inner_;
  int width_px_;
  int quality_;
  std::mutex mutex_;
  std::deque<std::pair<std::int64_t, std::string>> recent_;
};

using Emit = std::function<void(const nlohmann::json&)>;
int run_timeline_worker(const std::string& spec, double heartbeat_s, const Emit& emit,
                        const std::atomic<bool>& interrupted);

}  // namespace gbdcs::app
