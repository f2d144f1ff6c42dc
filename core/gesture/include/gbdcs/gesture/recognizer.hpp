// GestureRecognizer: the strategy that turns one hand into one gesture guess.
//
// Inputs   contracts::Landmarks, one hand, one frame (normalised image coordinates).
// Outputs  Recognition: the gesture (NONE when the hand shows nothing of the vocabulary) and
//          a confidence in [0, 1]. Stateless per frame: smoothing over frames is the
//          GestureEngine's job. Must never throw on odd input (NaN, collapsed hands): such a
//          hand is NONE with confidence 0.
// Implementations: RuleBasedRecognizer (rule_based_recognizer.hpp); a learned one can follow.
#pragma once

#include <string_view>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::gesture {

struct Recognition {
  contracts::GestureType gesture = contracts::GestureType::kNone;
  double confidence = 0;  // [0, 1]
};

class GestureRecognizer {
 public:
  virtual ~GestureRecognizer() = default;
  // A view of static storage (a string literal): callers keep it after the recognizer is
  // gone, e.g. GestureEngine::recognizer_name() across a run-time swap.
  virtual std::string_view name() const = 0;
  virtual Recognition recognize(const contracts::Landmarks& hand) const = 0;
};

}  // namespace gbdcs::gesture
