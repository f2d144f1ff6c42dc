// Random synthetic hands for the gesture tests: a pose from the library, placed at random.
#pragma once

#include <algorithm>
#include <random>

#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::gesture::testing {

// The spread of placements the recognizer must cope with.
struct PlacementRange {
  double min_size = 0.15;  // hand length / frame height
  double max_size = 0.6;
  double max_roll_deg = 180;
  double max_yaw_deg = 30;
  double max_pitch_deg = 15;
  double landmark_noise = 0.01;  // sigma as a fraction of the hand length (z: twice that)
};

// Direction gestures are defined by where they point, so they get a smaller roll.
inline PlacementRange range_for(sim::PoseName pose) {
  PlacementRange r;
  if (sim::is_direction_pose(pose)) r.max_roll_deg = 25;
  return r;
}

inline sim::Placement random_placement(std::mt19937& rng, const PlacementRange& r) {
  sim::Placement p;
  p.size = sim::uniform(rng, r.min_size, r.max_size);
  // Keep the palm centre far enough in that the whole hand stays in the frame.
  const double margin = 0.5 * p.size;
  p.center_y = sim::uniform(rng, std::min(0.5, margin), std::max(0.5, 1 - margin));
  p.center_x = sim::uniform(rng, std::min(0.5, 0.75 * margin), std::max(0.5, 1 - 0.75 * margin));
  p.roll_deg = sim::uniform(rng, -r.max_roll_deg, r.max_roll_deg);
  p.yaw_deg = sim::uniform(rng, -r.max_yaw_deg, r.max_yaw_deg);
  p.pitch_deg = sim::uniform(rng, -r.max_pitch_deg, r.max_pitch_deg);
  p.handedness = sim::uniform(rng, 0, 1) < 0.5 ? contracts::Handedness::kLeft
                                               : contracts::Handedness::kRight;
  p.presence = sim::uniform(rng, 0.85, 1.0);
  return p;
}

inline contracts::Landmarks random_hand(sim::PoseName pose, std::mt19937& rng,
                                        const PlacementRange& r) {
  const sim::HandPose hand_pose = sim::pose_for(pose, rng);
  const sim::Placement placement = random_placement(rng, r);
  contracts::Landmarks hand = sim::synthesize(hand_pose, placement);
  sim::add_landmark_noise(hand, r.landmark_noise, placement.size, rng);
  return hand;
}

inline contracts::GestureType expected_gesture(sim::PoseName pose) {
  return sim::gesture_of(pose).value_or(contracts::GestureType::kNone);
}

}  // namespace gbdcs::gesture::testing
