// VisionPipeline: four stage threads joined by bounded queues; metrics and health.
#include "gbdcs/vision/vision_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace gbdcs::vision {

std::optional<contracts::Landmarks> strongest_hand(const std::vector<contracts::Landmarks>& hands) {
  const contracts::Landmarks* best = nullptr;
  for (const auto& h : hands) {
    if (best == nullptr || h.score > best->score) best = &h;
  }
  if (best == nullptr) return std::nullopt;
  return *best;
}
namespace {

using contracts::Duration;

constexpr std::size_t kLatencySlot = kStageCount;  // after the stages in Timings
constexpr Duration kFpsWindow = std::chrono::seconds(1);

// Set on each stage thread, so stop() from the results callback does not join itself.
thread_local const void* t_pipeline = nullptr;

double to_ms(Duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// Nearest-rank percentile of a sorted sample.
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

class ClassifierRecognizer final : public gesture::GestureRecognizer {
 public:
  explicit ClassifierRecognizer(const HandClassifier& classifier) : classifier_(classifier) {}
  std::string_view name() const override { return "rule_based"; }
  gesture::Recognition recognize(const contracts::Landmarks& hand) const override {
    return classifier_.recognize(hand);
  }

 private:
  const HandClassifier& classifier_;
};

const PipelineOptions& checked(const PipelineOptions& options) {
  validate(options);
  return options;
}

// "auto" (no policy given): drop the oldest frame for a live source, block for a file.
OverflowPolicy overflow_policy(const PipelineOptions& options, bool live) {
  return options.policy.value_or(live ? OverflowPolicy::kDropOldest : OverflowPolicy::kBlock);
}

CaptureSource& non_null(const std::unique_ptr<CaptureSource>& source) {
  if (!source) throw std::invalid_argument("VisionPipeline: no capture source");
  return *source;
}

void preprocess(Frame& frame, int resize_width, int resize_height) {
  if (frame.order == PixelOrder::kBgr) {
    cv::Mat rgb;
    cv::cvtColor(frame.rgb, rgb, cv::COLOR_BGR2RGB);
    frame.rgb = rgb;
    frame.order = PixelOrder::kRgb;
  }
  if (resize_width <= 0 && resize_height <= 0) return;
  const double w = frame.rgb.cols;
  const double h = frame.rgb.rows;
  const int out_w = resize_width > 0
                        ? resize_width
                        : std::max(1, static_cast<int>(std::lround(w * resize_height / h)));
  const int out_h = resize_height > 0
                        ? resize_height
                        : std::max(1, static_cast<int>(std::lround(h * resize_width / w)));
  if (out_w == frame.rgb.cols && out_h == frame.rgb.rows) return;
  cv::Mat resized;
  const bool shrinking = out_w * out_h < frame.rgb.cols * frame.rgb.rows;
  cv::resize(frame.rgb, resized, cv::Size(out_w, out_h), 0, 0,
             shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
  frame.rgb = resized;
}

}  // namespace

// The last `window` samples of each stage and of the end-to-end latency, in ms.
class VisionPipeline::Timings {
 public:
  explicit Timings(std::size_t window) : window_(window) {}
  void add(std::size_t slot, double ms) {
    auto& s = samples_[slot];
    s.push_back(ms);
    if (s.size() > window_) s.pop_front();
  }
  StageTiming summary(std::size_t slot) const {
    std::vector<double> sorted(samples_[slot].begin(), samples_[slot].end());
    std::sort(sorted.begin(), sorted.end());
    StageTiming t;
    t.samples = static_cast<std::int64_t>(sorted.size());
    t.p50_ms = percentile(sorted, 0.50);
    t.p95_ms = percentile(sorted, 0.95);
    t.max_ms = sorted.empty() ? 0 : sorted.back();
    return t;
  }

 private:
  std::size_t window_;
  std::array<std::deque<double>, kStageCount + 1> samples_;
};

VisionPipeline::VisionPipeline(std::unique_ptr<CaptureSource> source,
                               std::unique_ptr<HandFinder> finder, const contracts::Clock& clock,
                               ResultCallback on_result, PipelineOptions options)
    : clock_(clock),
      options_(checked(options)),
      source_(std::move(source)),
      finder_(std::move(finder)),
      on_result_(std::move(on_result)),
      live_(non_null(source_).live()),
      source_name_(source_->describe()),
      policy_(overflow_policy(options_, live_)),
      classifier_(options_.recognizer),
      engine_(clock, std::make_unique<ClassifierRecognizer>(classifier_), options_.engine),
      to_preprocess_(static_cast<std::size_t>(options_.queue_capacity), policy_),
      to_landmarks_(static_cast<std::size_t>(options_.queue_capacity), policy_),
      to_classify_(static_cast<std::size_t>(options_.queue_capacity), policy_),
      timings_(std::make_unique<Timings>(static_cast<std::size_t>(options_.timing_window))) {
  if (!finder_) throw std::invalid_argument("VisionPipeline: no hand finder");
  if (!on_result_) throw std::invalid_argument("VisionPipeline: no results callback");
}

VisionPipeline::~VisionPipeline() {
  stop();
}

void VisionPipeline::start() {
  {
    std::lock_guard lock(state_mutex_);
    if (started_) throw std::logic_error("VisionPipeline::start() called twice");
    started_ = true;
    started_at_ = last_frame_at_ = clock_.now();
    stages_running_ = static_cast<int>(kStageCount);
  }
  std::lock_guard join(join_mutex_);
  threads_.emplace_back([this] { run_stage(Stage::kCapture, &VisionPipeline::capture_loop); });
  threads_.emplace_back(
      [this] { run_stage(Stage::kPreprocess, &VisionPipeline::preprocess_loop); });
  threads_.emplace_back([this] { run_stage(Stage::kLandmarks, &VisionPipeline::landmarks_loop); });
  threads_.emplace_back([this] { run_stage(Stage::kClassify, &VisionPipeline::classify_loop); });
}

void VisionPipeline::stop() {
  {
    std::lock_guard lock(state_mutex_);
    if (!started_) return;  // nothing runs yet; start() may still follow
  }
  stop_requested_ = true;
  shut_queues();
  if (t_pipeline == this) return;  // a stage thread cannot join itself
  std::lock_guard join(join_mutex_);
  for (auto& t : threads_) {
    if (t.joinable()) t.join();
  }
}

void VisionPipeline::wait() {
  std::unique_lock lock(state_mutex_);
  finished_cv_.wait(lock, [&] { return !started_ || finished_; });
}

bool VisionPipeline::wait_for(std::chrono::milliseconds timeout) {
  std::unique_lock lock(state_mutex_);
  return finished_cv_.wait_for(lock, timeout, [&] { return !started_ || finished_; });
}

void VisionPipeline::run_stage(Stage stage, void (VisionPipeline::*loop)()) {
  t_pipeline = this;
  try {
    (this->*loop)();
  } catch (const std::exception& e) {
    fail(std::string(to_string(stage)) + " stage: " + e.what());
  } catch (...) {
    fail(std::string(to_string(stage)) + " stage: unknown exception");
  }
  // A stage that ends for any reason lets the neighbours end too.
  switch (stage) {
    case Stage::kCapture:
      to_preprocess_.close();
      break;
    case Stage::kPreprocess:
      to_landmarks_.close();
      break;
    case Stage::kLandmarks:
      to_classify_.close();
      break;
    case Stage::kClassify:
      shut_queues();
      break;
  }
  std::lock_guard lock(state_mutex_);
  if (--stages_running_ == 0) {
    finished_ = true;
    finished_cv_.notify_all();
  }
}

void VisionPipeline::fail(const std::string& reason) {
  {
    std::lock_guard lock(state_mutex_);
    if (failure_.empty()) failure_ = reason;
  }
  stop_requested_ = true;
  shut_queues();
}

void VisionPipeline::shut_queues() {
  to_preprocess_.close();
  to_landmarks_.close();
  to_classify_.close();
  to_preprocess_.discard();
  to_landmarks_.discard();
  to_classify_.discard();
}

void VisionPipeline::record(Stage stage, Duration elapsed) {
  std::lock_guard lock(state_mutex_);
  timings_->add(static_cast<std::size_t>(stage), to_ms(elapsed));
}

void VisionPipeline::capture_loop() {
  while (!stop_requested_) {
    const auto t0 = clock_.now();
    std::optional<Frame> frame = source_->next();
    const auto t1 = clock_.now();
    if (!frame) {
      if (live_ && !stop_requested_) {
        fail(source_name_ +
             " ended unexpectedly (a live source should not end: unplugged, "
             "or the stream was closed)");
      }
      return;
    }
    {
      std::lock_guard lock(state_mutex_);
      ++frames_captured_;
      last_frame_at_ = t1;
      timings_->add(static_cast<std::size_t>(Stage::kCapture), to_ms(t1 - t0));
    }
    if (!to_preprocess_.push(std::move(*frame))) return;
  }
}

void VisionPipeline::preprocess_loop() {
  while (auto frame = to_preprocess_.pop()) {
    if (stop_requested_) return;
    const auto t0 = clock_.now();
    preprocess(*frame, options_.resize_width, options_.resize_height);
    record(Stage::kPreprocess, clock_.now() - t0);
    if (!to_landmarks_.push(std::move(*frame))) return;
  }
}

void VisionPipeline::landmarks_loop() {
  while (auto frame = to_landmarks_.pop()) {
    if (stop_requested_) return;
    const auto t0 = clock_.now();
    Located located;
    located.hands = finder_->find(frame->rgb);
    record(Stage::kLandmarks, clock_.now() - t0);
    located.width = frame->rgb.cols;
    located.height = frame->rgb.rows;
    frame->rgb.release();
    located.frame = std::move(*frame);
    if (!to_classify_.push(std::move(located))) return;
  }
}

void VisionPipeline::classify_loop() {
  while (auto item = to_classify_.pop()) {
    if (stop_requested_) return;
    const auto t0 = clock_.now();
    FrameResult r;
    r.frame_id = item->frame.frame_id;
    r.capture_time = item->frame.capture_time;
    r.capture_utc = item->frame.capture_utc;
    r.source = std::move(item->frame.source);
    r.width = item->width;
    r.height = item->height;
    classifier_.set_frame_size(r.width, r.height);
    r.hands = classifier_.classify(item->hands);
    r.gesture_event = engine_.process(strongest_hand(item->hands), r.frame_id);
    const auto t1 = clock_.now();
    r.latency = t1 - r.capture_time;
    {
      std::lock_guard lock(state_mutex_);
      timings_->add(static_cast<std::size_t>(Stage::kClassify), to_ms(t1 - t0));
      timings_->add(kLatencySlot, to_ms(r.latency));
      ++frames_done_;
      done_times_.push_back(t1);
      while (!done_times_.empty() && done_times_.front() < t1 - kFpsWindow) done_times_.pop_front();
    }
    on_result_(r);
  }
}

PipelineMetrics metrics_before_start(const PipelineOptions& options, std::string source,
                                     bool live, std::string reason) {
  validate(options);
  PipelineMetrics m;
  m.healthy = false;
  m.reason = std::move(reason);
  m.source = std::move(source);
  m.live = live;
  m.policy = overflow_policy(options, live);
  for (auto& q : m.queues) q.capacity = static_cast<std::size_t>(options.queue_capacity);
  return m;
}

PipelineMetrics VisionPipeline::metrics() const {
  PipelineMetrics m;
  m.source = source_name_;
  m.live = live_;
  m.policy = policy_;
  const BoundedQueue<Frame>* frame_queues[] = {&to_preprocess_, &to_landmarks_};
  for (std::size_t i = 0; i < 2; ++i) {
    m.queues[i] = {frame_queues[i]->depth(), frame_queues[i]->max_depth(),
                   frame_queues[i]->capacity(), frame_queues[i]->dropped()};
  }
  m.queues[2] = {to_classify_.depth(), to_classify_.max_depth(), to_classify_.capacity(),
                 to_classify_.dropped()};
  for (const auto& q : m.queues) m.frames_dropped += q.dropped;

  const auto now = clock_.now();
  std::lock_guard lock(state_mutex_);
  for (std::size_t i = 0; i < kStageCount; ++i) m.stages[i] = timings_->summary(i);
  m.latency = timings_->summary(kLatencySlot);
  m.running = started_ && !finished_;
  m.finished = finished_;
  m.frames_captured = frames_captured_;
  m.frames_done = frames_done_;
  const auto recent = std::count_if(done_times_.begin(), done_times_.end(),
                                    [&](Duration t) { return t >= now - kFpsWindow; });
  const Duration span = std::min(kFpsWindow, now - started_at_);
  m.fps = started_ && span > Duration::zero()
              ? static_cast<double>(recent) / contracts::to_seconds(span)
              : 0;
  m.healthy = failure_.empty();
  m.reason = failure_;
  const Duration silent = now - last_frame_at_;
  if (m.healthy && live_ && m.running &&
      silent > contracts::from_seconds(options_.stall_timeout_s)) {
    char numbers[64];
    std::snprintf(numbers, sizeof numbers, " for %.2f s (limit %.2f s)",
                  contracts::to_seconds(silent), options_.stall_timeout_s);
    m.healthy = false;
    m.reason = "no frame from " + source_name_ + numbers;
  }
  return m;
}

}  // namespace gbdcs::vision
