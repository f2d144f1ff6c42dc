// VisionPipeline: capture -> preprocess -> landmarks -> classify, pipes and filters.
//
// Stages (each its own thread, a BoundedQueue in front of every stage but the first)
//   capture     CaptureSource::next(); stamps nothing itself (the source stamps the frame).
//   preprocess  BGR -> RGB when the source delivers BGR; optional resize (resize_width/height).
//   landmarks   HandFinder::find(rgb): the hands in the frame (the real finder wraps
//               HandTracker; tests use a fake).
//   classify    the rule-based recogniser on every hand (with the frame's aspect ratio); the
//               strongest hand (highest presence score, the first on a tie) goes to the
//               GestureEngine, no hand counts as NONE; then the results callback.
// Outputs
//   on_result(FrameResult) once per frame that made it through, in capture order, on the
//   classify thread (keep it short: it holds up the stage). Frames dropped by a queue never
//   reach it (a gap in frame_id).
//   metrics(): a PipelineMetrics snapshot (thread-safe, any time).
// Queue policy: drop-oldest for a live source (a stale frame is worth less than a new one),
// block for an offline one (no frame lost); PipelineOptions::policy overrides.
// Health: unhealthy, with a reason, when the source throws, a live source ends, a stage throws
// (the pipeline then stops), or a live source has produced no frame for more than
// stall_timeout_s (healthy again with the next frame). An offline source reaching its end is
// healthy and finishes the pipeline once the last frame is through.
// Time: every timing and the stall check read the injected Clock (ms in the metrics).
// Options (JSON keys = field names; unknown keys rejected with std::invalid_argument)
//   queue_capacity 2 (frames per queue, >= 1), policy "auto" | "drop_oldest" | "block",
//   resize_width 0, resize_height 0 (px; 0 and 0 = keep, one 0 = keep the aspect ratio),
//   stall_timeout_s 0.5 (> 0), timing_window 120 (samples per stage for p50/p95, >= 1),
//   engine {GestureEngineOptions}, recognizer {RuleBasedOptions}.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/vision/bounded_queue.hpp"
#include "gbdcs/vision/capture.hpp"
#include "gbdcs/vision/frame.hpp"

namespace gbdcs::vision {

// What the landmarks stage runs: the hands in one RGB frame (CV_8UC3), landmarks in
// normalised image coordinates, score = presence. Called from one thread at a time.
class HandFinder {
 public:
  virtual ~HandFinder() = default;
  virtual std::vector<contracts::Landmarks> find(const cv::Mat& rgb) = 0;
  virtual void reset() {}  // forget tracking state
};

// The hand the gesture engine follows: the highest presence, the first on a tie (the
// pipeline's classify stage and the scenario runner's pixel cameras).
std::optional<contracts::Landmarks> strongest_hand(const std::vector<contracts::Landmarks>& hands);

struct TrackerOptions;  // gbdcs/vision/hand_tracker.hpp
// The real finder: a HandTracker (loads the models; throws what HandTracker throws).
std::unique_ptr<HandFinder> make_tracker_finder(const TrackerOptions& options,
                                                const contracts::Clock& clock);

struct HandResult {
  contracts::Landmarks landmarks;
  contracts::GestureType gesture = contracts::GestureType::kNone;
  double confidence = 0;
};

// The rule-based recogniser with the aspect ratio of the frame the landmarks came from
// (landmarks are normalised separately in x and y; the rules need true angles).
class HandClassifier {
 public:
  explicit HandClassifier(gesture::RuleBasedOptions options = {});  // validates; may throw
  void set_frame_size(int width_px, int height_px);                 // ignored unless both > 0
  gesture::Recognition recognize(const contracts::Landmarks& hand) const;
  std::vector<HandResult> classify(const std::vector<contracts::Landmarks>& hands) const;

 private:
  gesture::RuleBasedOptions options_;
  gesture::RuleBasedRecognizer recognizer_;
};

struct FrameResult {
  std::int64_t frame_id = 0;
  contracts::Duration capture_time{};
  contracts::UtcTime capture_utc{};
  std::string source;
  int width = 0;  // of the frame the landmarks were found on (after any resize), px
  int height = 0;
  std::vector<HandResult> hands;
  std::optional<contracts::GestureEvent> gesture_event;
  contracts::Duration latency{};  // capture -> classified
};

enum class Stage { kCapture, kPreprocess, kLandmarks, kClassify };
inline constexpr std::size_t kStageCount = 4;
std::string_view to_string(Stage s);  // "capture", "preprocess", "landmarks", "classify"

struct StageTiming {
  double p50_ms = 0;
  double p95_ms = 0;
  double max_ms = 0;
  std::int64_t samples = 0;  // in the window
};

// The queue in front of a stage (preprocess, landmarks, classify).
struct QueueMetrics {
  std::size_t depth = 0;
  std::size_t max_depth = 0;
  std::size_t capacity = 0;
  std::int64_t dropped = 0;
};
inline constexpr std::size_t kQueueCount = 3;

struct PipelineMetrics {
  bool healthy = true;
  std::string reason;  // why not healthy; empty when healthy
  bool running = false;
  bool finished = false;  // every stage has stopped (end of stream, stop() or failure)
  std::string source;
  bool live = false;
  OverflowPolicy policy = OverflowPolicy::kBlock;
  double fps = 0;  // frames through classify in the last second
  std::int64_t frames_captured = 0;
  std::int64_t frames_done = 0;
  std::int64_t frames_dropped = 0;                 // by the queues
  std::array<StageTiming, kStageCount> stages{};   // indexed by Stage
  std::array<QueueMetrics, kQueueCount> queues{};  // [0] preprocess, [1] landmarks, [2] classify
  StageTiming latency{};                           // capture -> classified
};

struct PipelineOptions {
  int queue_capacity = 2;
  std::optional<OverflowPolicy> policy;  // nullopt = auto (by CaptureSource::live())
  int resize_width = 0;
  int resize_height = 0;
  double stall_timeout_s = 0.5;
  int timing_window = 120;
  gesture::GestureEngineOptions engine;
  gesture::RuleBasedOptions recognizer;
};

PipelineOptions pipeline_options_from_json(const nlohmann::json& doc);  // validates
void validate(const PipelineOptions& options);  // throws std::invalid_argument naming the key

// The metrics of a pipeline that is not running yet (its camera still being prepared, say):
// not healthy, for `reason`; the queues empty, at the capacity `options` will give them. What
// a worker reports in its heartbeat before it has a pipeline (vision_heartbeat wants every
// queue's capacity >= 1).
PipelineMetrics metrics_before_start(const PipelineOptions& options, std::string source,
                                     bool live, std::string reason);

class VisionPipeline {
 public:
  using ResultCallback = std::function<void(const FrameResult&)>;

  // Throws std::invalid_argument for a null source or finder, or invalid options. The clock
  // must outlive the pipeline. Nothing runs until start().
  VisionPipeline(std::unique_ptr<CaptureSource> source, std::unique_ptr<HandFinder> finder,
                 const contracts::Clock& clock, ResultCallback on_result,
                 PipelineOptions options = {});
  ~VisionPipeline();  // stop()
  VisionPipeline(const VisionPipeline&) = delete;
  VisionPipeline& operator=(const VisionPipeline&) = delete;

  void start();  // throws std::logic_error when called twice
  // Stops every stage, discarding queued frames, and joins the threads. Idempotent. Called
  // from the results callback it only asks the stages to stop (the owner's stop() or the
  // destructor joins).
  void stop();
  // Until the pipeline has finished: an offline source read to its end with every frame
  // through, a failure, or stop(). wait_for() gives up after `timeout` (real time) and
  // returns whether it finished.
  void wait();
  bool wait_for(std::chrono::milliseconds timeout);

  PipelineMetrics metrics() const;

 private:
  class Timings;
  struct Located {
    Frame frame;  // pixels released once the landmarks are found
    int width = 0;
    int height = 0;
    std::vector<contracts::Landmarks> hands;
  };

  void capture_loop();
  void preprocess_loop();
  void landmarks_loop();
  void classify_loop();
  void run_stage(Stage stage, void (VisionPipeline::*loop)());
  void fail(const std::string& reason);
  void shut_queues();
  void record(Stage stage, contracts::Duration elapsed);

  const contracts::Clock& clock_;
  const PipelineOptions options_;
  std::unique_ptr<CaptureSource> source_;
  std::unique_ptr<HandFinder> finder_;
  ResultCallback on_result_;
  const bool live_;
  const std::string source_name_;
  const OverflowPolicy policy_;
  HandClassifier classifier_;
  gesture::GestureEngine engine_;

  BoundedQueue<Frame> to_preprocess_;
  BoundedQueue<Frame> to_landmarks_;
  BoundedQueue<Located> to_classify_;

  std::atomic<bool> stop_requested_{false};
  std::unique_ptr<Timings> timings_;  // guarded by state_mutex_
  mutable std::mutex state_mutex_;
  std::condition_variable finished_cv_;
  bool started_ = false;
  bool finished_ = false;
  int stages_running_ = 0;
  std::string failure_;  // first failure; empty when none
  contracts::Duration started_at_{};
  contracts::Duration last_frame_at_{};
  std::int64_t frames_captured_ = 0;
  std::int64_t frames_done_ = 0;
  std::deque<contracts::Duration> done_times_;  // completions in the last second

  std::mutex join_mutex_;
  std::vector<std::thread> threads_;
};

}  // namespace gbdcs::vision
