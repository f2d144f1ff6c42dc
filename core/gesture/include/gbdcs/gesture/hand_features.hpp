// Hand features: the few numbers the rule-based recognizer decides on, from 21 landmarks.
//
// Inputs
//   contracts::Landmarks  21 points, normalised image coordinates (x by frame width, y by
//                         frame height, z in the scale of x).
//   aspect_ratio          frame width / height; undoes the anisotropic normalisation so that
//                         angles are true (default 4:3 in RuleBasedOptions).
//   depth_weight          multiplier on z, in [0, 1]: 1 trusts the landmark model's depth,
//                         0 works on the image projection alone.
// Outputs
//   HandFeatures: per-finger curl (deg), thumb bend (deg) and reach (palm sizes), the angle
//   between index and middle (deg), and the image direction of the index and of the thumb
//   (deg, 0 = up, 90 = right, -90 = left, 180 = down) with how much of each digit lies in the
//   image plane. Angles and distance ratios are invariant to scale, in-plane rotation and
//   handedness. `valid` is false for degenerate input (non-finite coordinates, a palm of no
//   size); the other fields are then meaningless.
#pragma once

#include <array>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::gesture {

struct HandFeatures {
  bool valid = false;
  double palm_size = 0;  // mean wrist-to-knuckle distance, isotropic image units
  // Index, middle, ring, pinky: angle between the palm bone (wrist -> knuckle) and the
  // finger (knuckle -> tip). ~0-20 straight, ~80 half closed, ~140 in a tight fist.
  std::array<double, 4> finger_curl_deg{};
  double thumb_bend_deg = 0;   // angle between thumb metacarpal (CMC -> MCP) and MCP -> tip
  double thumb_lateral = 0;    // thumb tip across the palm toward the index side, palm sizes
                               // (~1 stuck out, ~0 over the middle finger, < 0 across the palm)
  double thumb_reach = 0;      // |thumb tip - pinky knuckle| / palm_size
  double index_middle_spread_deg = 0;  // angle between index and middle, knuckle to tip
  double index_direction_deg = 0;    // image direction of index knuckle -> tip
  double index_in_plane = 0;         // its image length / its 3-D length, in [0, 1]
  double thumb_direction_deg = 0;    // image direction of thumb MCP -> tip
  double thumb_in_plane = 0;
};

HandFeatures extract_features(const contracts::Landmarks& hand, double aspect_ratio,
                              double depth_weight);

// Smallest absolute difference between two directions (deg), in [0, 180].
double angle_between_directions_deg(double a_deg, double b_deg);

}  // namespace gbdcs::gesture
