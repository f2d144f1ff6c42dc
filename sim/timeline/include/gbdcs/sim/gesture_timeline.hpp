// GestureTimeline: a landmark-level "camera" for fast logic runs (`gbdcs fly`, logic
// scenarios): a scripted list of hand poses turned into the 21 landmarks a tracker would
// report, frame by frame, with seeded variation and smooth transitions.
//
// File (JSON, see docs/TIMELINES.md):
//   {"name": "demo", "seed": 7, "fps": 30, "noise": 0.004,
//    "placement": {"center_x": 0.5, "center_y": 0.5, "size": 0.35, "roll_deg": 0,
//                  "yaw_deg": 0, "pitch_deg": 0, "handedness": "Right"},
//    "segments": [{"pose": "NO_HAND", "duration_s": 1.0},
//                 {"pose": "THUMB_UP", "duration_s": 1.5, "transition_s": 0.3}, ...]}
//   pose: a PoseName ("OPEN_PALM", "FOUR_FINGERS", ...) or "NO_HAND"; transition_s (default
//   0.25) blends from the previous pose; a segment may override any placement field.
// Output: frame(i) -> the hand (or nullopt) and the pose label of frame i at time i / fps.
// Bad files: TimelineError naming the segment and field.
#pragma once

#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::sim {

class TimelineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TimelineSegment {
  std::optional<PoseName> pose;  // nullopt = no hand in view
  double duration_s = 1;
  double transition_s = 0.25;
  Placement placement;
};

struct TimelineFrame {
  std::optional<contracts::Landmarks> hand;
  std::string label;  // the segment's pose name ("NO_HAND" when empty)
  std::optional<contracts::GestureType> deliberate;  // the gesture, if the pose is one
  double time_s = 0;
  std::size_t segment = 0;
};

class GestureTimeline {
 public:
  static GestureTimeline from_json(const nlohmann::json& doc);  // throws TimelineError
  static GestureTimeline load_file(const std::string& path);

  const std::string& name() const { return name_; }
  double fps() const { return fps_; }
  double duration_s() const;
  std::size_t frame_count() const;
  const std::vector<TimelineSegment>& segments() const { return segments_; }
  // Frames must be asked for in order (variation is drawn from one seeded generator).
  TimelineFrame next_frame();

 private:
  std::string name_;
  unsigned seed_ = 1;
  double fps_ = 30;
  double noise_ = 0.004;
  std::vector<TimelineSegment> segments_;
  std::vector<HandPose> poses_;  // one drawn per segment
  std::mt19937 rng_;
  std::size_t next_index_ = 0;
};

}  // namespace gbdcs::sim
