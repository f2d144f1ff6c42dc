// GestureEngine: the stabiliser between the per-frame recognizer and the commands.
//
// Inputs   process(hand, frame_id) once per frame: the hand's landmarks, or nullopt when no
//          hand was found (counts as NONE).
// Outputs  at most one GestureEvent per frame, never for NONE:
//            onset   (repeat = false) when a gesture other than the active one has
//                    agree_frames of the last window_frames frames, each recognised with
//                    confidence >= min_confidence (and more such frames than the active one);
//            refresh (repeat = true) on a frame that still shows the active gesture, at most
//                    once per repeat_interval_s on the injected clock.
//          The active gesture is released (no event) when fewer than release_frames of the
//          window agree with it; that gap between onset (k) and release is the hysteresis
//          that lets a held gesture survive a few noisy frames. Going from A straight to B
//          needs k of n for B too, so the in-between frames of a transition emit nothing.
//          Event confidence = mean confidence of the agreeing frames in the window;
//          timestamp = clock.utc_now(); handedness = the latest hand's.
// Options (JSON keys = field names; unknown keys, wrong types, bad values rejected with
// std::invalid_argument naming the key)
//   window_frames 7 (n, 1..1000), agree_frames 5 (k, 1..n), release_frames 3 (1..k),
//   min_confidence 0.6 ([0, 1]), repeat_interval_s 0.5 (> 0, seconds of Clock::now()).
// Threads  every method is safe to call from any thread; set_recognizer() swaps the strategy
//          at run time and clears the window and the active gesture (so a gesture held
//          across a swap gets a fresh onset after k frames).
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/gesture/recognizer.hpp"

namespace gbdcs::gesture {

struct GestureEngineOptions {
  int window_frames = 7;
  int agree_frames = 5;
  int release_frames = 3;
  double min_confidence = 0.6;
  double repeat_interval_s = 0.5;
};

GestureEngineOptions gesture_engine_options_from_json(const nlohmann::json& doc);
nlohmann::json to_json(const GestureEngineOptions& options);
void validate(const GestureEngineOptions& options);  // throws std::invalid_argument

class GestureEngine {
 public:
  // Throws std::invalid_argument for a null recognizer or invalid options. The clock must
  // outlive the engine.
  GestureEngine(const contracts::Clock& clock, std::unique_ptr<GestureRecognizer> recognizer,
                GestureEngineOptions options = {});

  std::optional<contracts::GestureEvent> process(const std::optional<contracts::Landmarks>& hand,
                                                 std::int64_t frame_id);

  contracts::GestureType active() const;
  double active_confidence() const;
  void set_recognizer(std::unique_ptr<GestureRecognizer> recognizer);  // throws on null
  std::string_view recognizer_name() const;
  void reset();
  const GestureEngineOptions& options() const { return options_; }

 private:
  struct Vote {
    contracts::GestureType gesture = contracts::GestureType::kNone;
    double confidence = 0;
  };
  void reset_locked();
  contracts::GestureEvent make_event(std::int64_t frame_id, bool repeat) const;

  const contracts::Clock& clock_;
  const GestureEngineOptions options_;
  mutable std::mutex mutex_;
  std::unique_ptr<GestureRecognizer> recognizer_;
  std::deque<Vote> window_;
  contracts::GestureType active_ = contracts::GestureType::kNone;
  double active_confidence_ = 0;
  contracts::Duration last_event_at_{};
  contracts::Handedness last_handedness_ = contracts::Handedness::kRight;
};

}  // namespace gbdcs::gesture
