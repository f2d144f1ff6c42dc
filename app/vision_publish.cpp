#include "vision_publish.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/server/auth.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "gbdcs/vision/vision_messages.hpp"

namespace gbdcs::app {

using nlohmann::json;

json picture_message(const vision::Frame& frame, int width_px, int quality) {
  cv::Mat small, bgr;
  const double scale = std::min(1.0, static_cast<double>(width_px) / frame.rgb.cols);
  cv::resize(frame.rgb, small, cv::Size(), scale, scale, cv::INTER_AREA);
  if (frame.order == vision::PixelOrder::kRgb) {
    cv::cvtColor(small, bgr, cv::COLOR_RGB2BGR);
  } else {
    bgr = small;
  }
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return {{"type", "picture"},
          {"frame_id", frame.frame_id},
          {"capture_time", contracts::format_utc(frame.capture_utc)},
          {"width", bgr.cols},
          {"height", bgr.rows},
          {"jpeg", server::base64_encode(std::string_view(
                       reinterpret_cast<const char*>(bytes.data()), bytes.size()))}};
}

int run_timeline_worker(const std::string& spec, double heartbeat_s, const Emit& emit,
                        const std::atomic<bool>& interrupted) {
  const auto path = spec.substr(std::string("timeline:").size());
  auto timeline = sim::GestureTimeline::load_file(path);
  gesture::RuleBasedRecognizer recognizer;
  contracts::SteadyClock clock;
  const auto period = contracts::from_seconds(1.0 / timeline.fps());
  const auto frames = static_cast<std::int64_t>(timeline.frame_count());
  const auto start = std::chrono::steady_clock::now();
  auto next_beat = clock.now();
  vision::PipelineMetrics metrics;
  metrics.healthy = true;
  metrics.running = true;
  metrics.live = true;
  metrics.source = spec;
  metrics.fps = timeline.fps();
  for (auto& q : metrics.queues) q.capacity = 1;
  for (std::int64_t i = 0; !interrupted; ++i) {
    std::this_thread::sleep_until(start + period * i);
    json hands = json::array();
    if (i < frames) {
      if (auto hand = timeline.next_frame().hand) {
        const auto r = recognizer.recognize(*hand);
        json points = json::array();
        for (const auto& p : hand->points) points.push_back({p.x, p.y, p.z});
        hands.push_back({{"handedness", contracts::to_string(hand->handedness)},
                         {"score", std::clamp(hand->score, 0.0, 1.0)},
                         {"landmarks", points},
                         {"gesture", contracts::to_string(r.gesture)},
                         {"confidence", r.confidence}});
      }
    }
    metrics.frames_captured = metrics.frames_done = i + 1;
    emit({{"type", "frame"},
          {"frame_id", i},
          {"capture_time", contracts::format_utc(clock.utc_now())},
          {"source", spec},
          {"width", 640},
          {"height", 480},
          {"latency_ms", 0.0},
          {"hands", hands},
          {"gesture_event", nullptr}});
    if (clock.now() >= next_beat) {
      emit(vision::heartbeat_message(metrics, clock.utc_now()));
      next_beat = clock.now() + contracts::from_seconds(heartbeat_s);
    }
  }
  return 0;
}

}  // namespace gbdcs::app
