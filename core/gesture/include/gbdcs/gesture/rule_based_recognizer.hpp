// RuleBasedRecognizer: the gesture vocabulary as rules on joint angles and palm-normalised
// distances (see hand_features.hpp).
//
// Inputs   contracts::Landmarks of one hand.
// Outputs  Recognition. Each digit is read as extended, folded or unclear; the pattern picks
//          the gesture:
//            OPEN_PALM   all five extended          FIST        all five folded
//            THUMB_UP    thumb only, pointing up    THUMB_DOWN  thumb only, pointing down
//            POINT_LEFT / POINT_RIGHT / POINT_UP    index only, pointing that way in the image
//            VICTORY     index + middle, spread     I_LOVE_YOU  thumb + index + pinky
//          Pointing and victory need the thumb only not extended (folded or unclear; its
//          confidence is the margin by which it misses "extended"). Four folded
//          fingers with a straight thumb (bend <= thumb_aimed_max_bend_deg) aimed up or down,
//          its tip at least thumb_aimed_min_lateral toward the index side, read as the thumb
//          gesture even when the tip's lateral position says folded (a raised thumb seen
//          end-on); a fist's own thumb is bent or lies across the fingers. Four folded
//          fingers with a bent thumb (bend >= thumb_extended_max_bend_deg) whose tip lies
//          between the limits (beside the index) are a FIST.
//          Anything else is NONE: four fingers with the thumb folded, call, rock, OK, pinch,
//          half-closed, relaxed, an unclear digit, a direction off by more than the
//          tolerance. Shape gestures are invariant to scale, in-plane rotation and
//          handedness; direction gestures use the image direction of the digit.
//          Confidence: the smallest margin by which any deciding feature passes its
//          threshold, mapped to [0.4, 1] (0.4 = on the threshold, 1 = one transition width or
//          more past it), times the presence factor clamp((score - min_presence) /
//          (full_presence - min_presence), 0, 1). NONE carries the presence factor. Degenerate
//          input (non-finite, collapsed palm) or score < min_presence: NONE, confidence 0.
// Options (JSON keys = field names; defaults below; unknown keys and wrong types rejected
// with std::invalid_argument naming the key)
//   aspect_ratio 4/3 (frame width / height), depth_weight 1 (trust in z, [0, 1]),
//   finger_extended_max_curl_deg 35, finger_folded_min_curl_deg 90,
//   thumb_extended_min_lateral 0.45 and thumb_folded_max_lateral 0.3 (palm sizes),
//   thumb_extended_max_bend_deg 45, thumb_aimed_max_bend_deg 30 ([0, the extended limit];
//   0 turns the aimed-thumb rule off), thumb_aimed_min_lateral 0 (below the extended limit),
//   victory_min_spread_deg 10,
//   direction_tolerance_deg 35 (< 45 so that directions cannot overlap),
//   direction_min_in_plane 0.5 (a digit aimed at the camera has no image direction),
//   angle_transition_deg 15, lateral_transition 0.2, min_presence 0.2, full_presence 0.8.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "gbdcs/gesture/hand_features.hpp"
#include "gbdcs/gesture/recognizer.hpp"

namespace gbdcs::gesture {

struct RuleBasedOptions {
  double aspect_ratio = 4.0 / 3.0;
  double depth_weight = 1.0;
  double finger_extended_max_curl_deg = 35;
  double finger_folded_min_curl_deg = 90;
  double thumb_extended_min_lateral = 0.45;
  double thumb_folded_max_lateral = 0.3;
  double thumb_extended_max_bend_deg = 45;
  double thumb_aimed_max_bend_deg = 30;
  double thumb_aimed_min_lateral = 0;
  double victory_min_spread_deg = 10;
  double direction_tolerance_deg = 35;
  double direction_min_in_plane = 0.5;
  double angle_transition_deg = 15;
  double lateral_transition = 0.2;
  double min_presence = 0.2;
  double full_presence = 0.8;
};

// Throws std::invalid_argument naming the first offending key.
RuleBasedOptions rule_based_options_from_json(const nlohmann::json& doc);
nlohmann::json to_json(const RuleBasedOptions& options);
void validate(const RuleBasedOptions& options);

class RuleBasedRecognizer final : public GestureRecognizer {
 public:
  explicit RuleBasedRecognizer(RuleBasedOptions options = {});  // validates; may throw

  std::string_view name() const override { return "rule_based"; }
  Recognition recognize(const contracts::Landmarks& hand) const override;
  const RuleBasedOptions& options() const { return options_; }

 private:
  RuleBasedOptions options_;
};

}  // namespace gbdcs::gesture
