#include "gbdcs/gesture/gesture_engine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::gesture {
namespace {

using contracts::GestureType;

constexpr const char* kOwner = "GestureEngineOptions";
constexpr int kMaxWindowFrames = 1000;

std::size_t slot(GestureType g) { return static_cast<std::size_t>(g); }

}  // namespace

GestureEngineOptions gesture_engine_options_from_json(const nlohmann::json& doc) {
  GestureEngineOptions o;
  contracts::JsonOptionReader r(doc, kOwner);
  r.read("window_frames", o.window_frames);
  r.read("agree_frames", o.agree_frames);
  r.read("release_frames", o.release_frames);
  r.read("min_confidence", o.min_confidence);
  r.read("repeat_interval_s", o.repeat_interval_s);
  r.finish();
  validate(o);
  return o;
}

nlohmann::json to_json(const GestureEngineOptions& o) {
  return {{"window_frames", o.window_frames},
          {"agree_frames", o.agree_frames},
          {"release_frames", o.release_frames},
          {"min_confidence", o.min_confidence},
          {"repeat_interval_s", o.repeat_interval_s}};
}

void validate(const GestureEngineOptions& o) {
  using contracts::require;
  require(o.window_frames >= 1 && o.window_frames <= kMaxWindowFrames, kOwner, "window_frames",
          "must be in [1, " + std::to_string(kMaxWindowFrames) + "]");
  require(o.agree_frames >= 1 && o.agree_frames <= o.window_frames, kOwner, "agree_frames",
          "must be in [1, window_frames]");
  require(o.release_frames >= 1 && o.release_frames <= o.agree_frames, kOwner,
          "release_frames", "must be in [1, agree_frames]");
  require(std::isfinite(o.min_confidence) && o.min_confidence >= 0 && o.min_confidence <= 1,
          kOwner, "min_confidence", "must be in [0, 1]");
  require(std::isfinite(o.repeat_interval_s) && o.repeat_interval_s > 0, kOwner,
          "repeat_interval_s", "must be a finite number of seconds > 0");
}

GestureEngine::GestureEngine(const contracts::Clock& clock,
                             std::unique_ptr<GestureRecognizer> recognizer,
                             GestureEngineOptions options)
    : clock_(clock), options_(options), recognizer_(std::move(recognizer)) {
  validate(options_);
  if (!recognizer_) throw std::invalid_argument("GestureEngine: recognizer must not be null");
}

std::optional<contracts::GestureEvent> GestureEngine::process(
    const std::optional<contracts::Landmarks>& hand, std::int64_t frame_id) {
  std::lock_guard lock(mutex_);
  Vote vote;
  if (hand) {
    last_handedness_ = hand->handedness;
    const Recognition r = recognizer_->recognize(*hand);
    if (r.gesture != GestureType::kNone && std::isfinite(r.confidence) &&
        r.confidence >= options_.min_confidence) {
      vote = {r.gesture, std::min(r.confidence, 1.0)};
    }
  }
  window_.push_back(vote);
  while (window_.size() > static_cast<std::size_t>(options_.window_frames)) window_.pop_front();

  std::array<int, contracts::kAllGestures.size()> count{};
  std::array<double, contracts::kAllGestures.size()> confidence_sum{};
  for (const Vote& v : window_) {
    ++count[slot(v.gesture)];
    confidence_sum[slot(v.gesture)] += v.confidence;
  }
  auto mean_confidence = [&](GestureType g) {
    return count[slot(g)] > 0 ? confidence_sum[slot(g)] / count[slot(g)] : 0.0;
  };

  if (active_ != GestureType::kNone && count[slot(active_)] < options_.release_frames) {
    active_ = GestureType::kNone;
    active_confidence_ = 0;
  }

  // The strongest other gesture; on a tie (possible only when k <= n / 2) the newest wins.
  GestureType best = GestureType::kNone;
  for (auto it = window_.rbegin(); it != window_.rend(); ++it) {
    if (it->gesture != GestureType::kNone && it->gesture != active_ &&
        (best == GestureType::kNone || count[slot(it->gesture)] > count[slot(best)])) {
      best = it->gesture;
    }
  }
  if (best != GestureType::kNone && count[slot(best)] >= options_.agree_frames &&
      count[slot(best)] > count[slot(active_)]) {
    active_ = best;
    active_confidence_ = mean_confidence(best);
    last_event_at_ = clock_.now();
    return make_event(frame_id, false);
  }

  if (active_ == GestureType::kNone) return std::nullopt;
  active_confidence_ = mean_confidence(active_);
  const contracts::Duration now = clock_.now();
  if (vote.gesture == active_ &&
      now - last_event_at_ >= contracts::from_seconds(options_.repeat_interval_s)) {
    last_event_at_ = now;
    return make_event(frame_id, true);
  }
  return std::nullopt;
}

contracts::GestureEvent GestureEngine::make_event(std::int64_t frame_id, bool repeat) const {
  contracts::GestureEvent e;
  e.gesture = active_;
  e.confidence = active_confidence_;
  e.handedness = last_handedness_;
  e.frame_id = frame_id;
  e.timestamp = clock_.utc_now();
  e.repeat = repeat;
  return e;
}

contracts::GestureType GestureEngine::active() const {
  std::lock_guard lock(mutex_);
  return active_;
}

double GestureEngine::active_confidence() const {
  std::lock_guard lock(mutex_);
  return active_confidence_;
}

void GestureEngine::set_recognizer(std::unique_ptr<GestureRecognizer> recognizer) {
  if (!recognizer) throw std::invalid_argument("GestureEngine: recognizer must not be null");
  std::lock_guard lock(mutex_);
  recognizer_ = std::move(recognizer);
  reset_locked();
}

std::string_view GestureEngine::recognizer_name() const {
  std::lock_guard lock(mutex_);
  return recognizer_->name();
}

void GestureEngine::reset() {
  std::lock_guard lock(mutex_);
  reset_locked();
}

void GestureEngine::reset_locked() {
  window_.clear();
  active_ = GestureType::kNone;
  active_confidence_ = 0;
  last_event_at_ = {};
}

}  // namespace gbdcs::gesture
