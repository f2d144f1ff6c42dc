#include "gbdcs/gesture/rule_based_recognizer.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::gesture {
namespace {

using contracts::GestureType;

constexpr const char* kOwner = "RuleBasedOptions";
// How far past direction_min_in_plane a digit must lie for full confidence in its direction.
constexpr double kInPlaneTransition = 0.2;

enum class Digit { kExtended, kFolded, kUnclear };
constexpr Digit kE = Digit::kExtended;
constexpr Digit kF = Digit::kFolded;

struct Reading {
  Digit state = Digit::kUnclear;
  double confidence = 0;
  double extended = 0;  // the thumb's evidence for extended (>= 0 when it is)
};

// Evidence is the distance past a threshold in transition widths (>= 0 when passed).
double margin_confidence(double evidence) { return std::clamp(0.4 + 0.6 * evidence, 0.0, 1.0); }

Reading read_finger(double curl_deg, const RuleBasedOptions& o) {
  const double extended = (o.finger_extended_max_curl_deg - curl_deg) / o.angle_transition_deg;
  const double folded = (curl_deg - o.finger_folded_min_curl_deg) / o.angle_transition_deg;
  if (extended >= 0) return {Digit::kExtended, margin_confidence(extended)};
  if (folded >= 0) return {Digit::kFolded, margin_confidence(folded)};
  return {};
}

// The thumb is judged by where its tip is across the palm (out beside the index, or over
// or across the fingers) and, when out, by being straight: a hooked thumb is not showing.
Reading read_thumb(const HandFeatures& f, const RuleBasedOptions& o) {
  const double extended =
      std::min((f.thumb_lateral - o.thumb_extended_min_lateral) / o.lateral_transition,
               (o.thumb_extended_max_bend_deg - f.thumb_bend_deg) / o.angle_transition_deg);
  const double folded = (o.thumb_folded_max_lateral - f.thumb_lateral) / o.lateral_transition;
  if (extended >= 0) return {Digit::kExtended, margin_confidence(extended), extended};
  if (folded >= 0) return {Digit::kFolded, margin_confidence(folded), extended};
  return {Digit::kUnclear, 0, extended};
}

struct Target {
  double direction_deg;  // 0 = up, 90 = right
  GestureType gesture;
};

// The target the digit points at within the tolerance, if any. Targets are at least 90 deg
// apart and the tolerance is below 45, so at most one can match.
std::optional<Recognition> match_direction(double direction_deg, double in_plane,
                                           std::initializer_list<Target> targets,
                                           const RuleBasedOptions& o) {
  const double visible = (in_plane - o.direction_min_in_plane) / kInPlaneTransition;
  if (visible < 0) return std::nullopt;
  for (const Target& t : targets) {
    const double off = angle_between_directions_deg(direction_deg, t.direction_deg);
    if (off <= o.direction_tolerance_deg) {
      const double aimed = (o.direction_tolerance_deg - off) / o.angle_transition_deg;
      return Recognition{t.gesture, std::min(margin_confidence(aimed), margin_confidence(visible))};
    }
  }
  return std::nullopt;
}

}  // namespace

RuleBasedOptions rule_based_options_from_json(const nlohmann::json& doc) {
  RuleBasedOptions o;
  contracts::JsonOptionReader r(doc, kOwner);
  r.read("aspect_ratio", o.aspect_ratio);
  r.read("depth_weight", o.depth_weight);
  r.read("finger_extended_max_curl_deg", o.finger_extended_max_curl_deg);
  r.read("finger_folded_min_curl_deg", o.finger_folded_min_curl_deg);
  r.read("thumb_extended_min_lateral", o.thumb_extended_min_lateral);
  r.read("thumb_folded_max_lateral", o.thumb_folded_max_lateral);
  r.read("thumb_extended_max_bend_deg", o.thumb_extended_max_bend_deg);
  r.read("thumb_aimed_max_bend_deg", o.thumb_aimed_max_bend_deg);
  r.read("thumb_aimed_min_lateral", o.thumb_aimed_min_lateral);
  r.read("victory_min_spread_deg", o.victory_min_spread_deg);
  r.read("direction_tolerance_deg", o.direction_tolerance_deg);
  r.read("direction_min_in_plane", o.direction_min_in_plane);
  r.read("angle_transition_deg", o.angle_transition_deg);
  r.read("lateral_transition", o.lateral_transition);
  r.read("min_presence", o.min_presence);
  r.read("full_presence", o.full_presence);
  r.finish();
  validate(o);
  return o;
}

nlohmann::json to_json(const RuleBasedOptions& o) {
  return {{"aspect_ratio", o.aspect_ratio},
          {"depth_weight", o.depth_weight},
          {"finger_extended_max_curl_deg", o.finger_extended_max_curl_deg},
          {"finger_folded_min_curl_deg", o.finger_folded_min_curl_deg},
          {"thumb_extended_min_lateral", o.thumb_extended_min_lateral},
          {"thumb_folded_max_lateral", o.thumb_folded_max_lateral},
          {"thumb_extended_max_bend_deg", o.thumb_extended_max_bend_deg},
          {"thumb_aimed_max_bend_deg", o.thumb_aimed_max_bend_deg},
          {"thumb_aimed_min_lateral", o.thumb_aimed_min_lateral},
          {"victory_min_spread_deg", o.victory_min_spread_deg},
          {"direction_tolerance_deg", o.direction_tolerance_deg},
          {"direction_min_in_plane", o.direction_min_in_plane},
          {"angle_transition_deg", o.angle_transition_deg},
          {"lateral_transition", o.lateral_transition},
          {"min_presence", o.min_presence},
          {"full_presence", o.full_presence}};
}

void validate(const RuleBasedOptions& o) {
  const nlohmann::json all = to_json(o);
  for (const auto& [key, value] : all.items()) {
    contracts::require(std::isfinite(value.get<double>()), kOwner, key, "must be finite");
  }
  using contracts::require;
  require(o.aspect_ratio > 0, kOwner, "aspect_ratio", "must be > 0 (frame width / height)");
  require(o.depth_weight >= 0 && o.depth_weight <= 1, kOwner, "depth_weight",
          "must be in [0, 1]");
  require(o.finger_extended_max_curl_deg > 0, kOwner, "finger_extended_max_curl_deg",
          "must be > 0");
  require(o.finger_folded_min_curl_deg > o.finger_extended_max_curl_deg &&
              o.finger_folded_min_curl_deg < 180,
          kOwner, "finger_folded_min_curl_deg",
          "must be above finger_extended_max_curl_deg and below 180");
  require(o.thumb_folded_max_lateral < o.thumb_extended_min_lateral, kOwner,
          "thumb_folded_max_lateral", "must be below thumb_extended_min_lateral");
  require(o.thumb_extended_max_bend_deg > 0 && o.thumb_extended_max_bend_deg < 180, kOwner,
          "thumb_extended_max_bend_deg", "must be in (0, 180)");
  require(o.thumb_aimed_max_bend_deg >= 0 && o.thumb_aimed_max_bend_deg <= o.thumb_extended_max_bend_deg,
          kOwner, "thumb_aimed_max_bend_deg",
          "must be in [0, thumb_extended_max_bend_deg] (0 turns the rule off)");
  require(o.thumb_aimed_min_lateral < o.thumb_extended_min_lateral, kOwner,
          "thumb_aimed_min_lateral", "must be below thumb_extended_min_lateral");
  require(o.victory_min_spread_deg >= 0 && o.victory_min_spread_deg < 90, kOwner,
          "victory_min_spread_deg", "must be in [0, 90)");
  require(o.direction_tolerance_deg > 0 && o.direction_tolerance_deg < 45, kOwner,
          "direction_tolerance_deg", "must be in (0, 45) so that directions cannot overlap");
  require(o.direction_min_in_plane >= 0 && o.direction_min_in_plane < 1, kOwner,
          "direction_min_in_plane", "must be in [0, 1)");
  require(o.angle_transition_deg > 0, kOwner, "angle_transition_deg", "must be > 0");
  require(o.lateral_transition > 0, kOwner, "lateral_transition", "must be > 0");
  require(o.min_presence >= 0 && o.min_presence < o.full_presence, kOwner, "min_presence",
          "must be >= 0 and below full_presence");
  require(o.full_presence <= 1, kOwner, "full_presence", "must be <= 1");
}

RuleBasedRecognizer::RuleBasedRecognizer(RuleBasedOptions options) : options_(options) {
  validate(options_);
}

Recognition RuleBasedRecognizer::recognize(const contracts::Landmarks& hand) const {
  const RuleBasedOptions& o = options_;
  if (!std::isfinite(hand.score) || hand.score < o.min_presence) return {};
  const HandFeatures f = extract_features(hand, o.aspect_ratio, o.depth_weight);
  if (!f.valid) return {};
  const double presence =
      std::clamp((hand.score - o.min_presence) / (o.full_presence - o.min_presence), 0.0, 1.0);

  // thumb, index, middle, ring, pinky
  std::array<Reading, 5> digits{read_thumb(f, o)};
  for (std::size_t i = 0; i < 4; ++i) digits[i + 1] = read_finger(f.finger_curl_deg[i], o);

  // The four fingers as wanted: the smallest of their confidences.
  auto fingers = [&digits](std::array<Digit, 4> want) -> std::optional<double> {
    double confidence = 1;
    for (std::size_t i = 0; i < want.size(); ++i) {
      if (digits[i + 1].state != want[i]) return std::nullopt;
      confidence = std::min(confidence, digits[i + 1].confidence);
    }
    return confidence;
  };
  auto shape = [&](Digit thumb, std::array<Digit, 4> want) -> std::optional<double> {
    const auto c = fingers(want);
    if (!c || digits[0].state != thumb) return std::nullopt;
    return std::min(*c, digits[0].confidence);
  };
  // For pointing and victory the thumb only has to be not out: folded, or read unclear
  // (tucked beside the index, or hidden behind the hand). Its confidence is the margin by which
  // it misses "extended", so a thumb further in is never less sure (the folded limit plays no
  // part here).
  auto shape_thumb_in = [&](std::array<Digit, 4> want) -> std::optional<double> {
    const auto c = fingers(want);
    if (!c || digits[0].state == kE) return std::nullopt;
    return std::min(*c, margin_confidence(-digits[0].extended));
  };
  auto scaled = [presence](Recognition r) {
    r.confidence *= presence;
    return r;
  };
  auto with_shape = [&](std::optional<Recognition> r, double shape_confidence) -> Recognition {
    if (!r) return {GestureType::kNone, presence};
    r->confidence = std::min(r->confidence, shape_confidence);
    return scaled(*r);
  };
  auto thumb_gesture = [&] {
    return match_direction(f.thumb_direction_deg, f.thumb_in_plane,
                           {{0, GestureType::kThumbUp}, {180, GestureType::kThumbDown}}, o);
  };

  if (auto c = shape(kE, {kE, kE, kE, kE})) return scaled({GestureType::kOpenPalm, *c});
  // Four folded fingers: a fist or a thumb gesture, decided by the thumb.
  if (const auto c = fingers({kF, kF, kF, kF})) {
    const Reading& thumb = digits[0];
    if (thumb.state == kE) return with_shape(thumb_gesture(), std::min(*c, thumb.confidence));
    // A straight thumb aimed up or down, its tip on its own side of the palm: the thumb
    // gesture, even where the tip reads as over the fist (seen end-on, the tracker places a
    // raised thumb's tip over the folded fingers). A fist's own thumb is bent, or lies across
    // the fingers with its tip past the palm's middle.
    const double straight =
        (o.thumb_aimed_max_bend_deg - f.thumb_bend_deg) / o.angle_transition_deg;
    const double beside = (f.thumb_lateral - o.thumb_aimed_min_lateral) / o.lateral_transition;
    if (o.thumb_aimed_max_bend_deg > 0 && straight >= 0 && beside >= 0) {
      if (auto r = thumb_gesture()) {
        r->confidence = std::min(
            {r->confidence, margin_confidence(straight), margin_confidence(beside)});
        return with_shape(r, *c);
      }
    }
    if (thumb.state == kF) return scaled({GestureType::kFist, std::min(*c, thumb.confidence)});
    // A thumb beside the index (tip between the limits) makes a fist when it is bent, as a
    // fist's thumb is; a straight one there stays unclear, and so does a hooked thumb read out
    // (FIST is LAND).
    const double bent =
        (f.thumb_bend_deg - o.thumb_extended_max_bend_deg) / o.angle_transition_deg;
    if (f.thumb_lateral < o.thumb_extended_min_lateral && bent >= 0)
      return scaled({GestureType::kFist, std::min(*c, margin_confidence(bent))});
    return {GestureType::kNone, presence};
  }
  if (auto c = shape(kE, {kE, kF, kF, kE})) return scaled({GestureType::kILoveYou, *c});
  if (auto c = shape_thumb_in({kE, kE, kF, kF})) {
    const double spread = (f.index_middle_spread_deg - o.victory_min_spread_deg) /
                          o.angle_transition_deg;
    if (spread < 0) return {GestureType::kNone, presence};  // two fingers together
    return scaled({GestureType::kVictory, std::min(*c, margin_confidence(spread))});
  }
  if (auto c = shape_thumb_in({kE, kF, kF, kF})) {
    return with_shape(match_direction(f.index_direction_deg, f.index_in_plane,
                                      {{-90, GestureType::kPointLeft},
                                       {90, GestureType::kPointRight},
                                       {0, GestureType::kPointUp}},
                                      o),
                      *c);
  }
  return {GestureType::kNone, presence};
}

}  // namespace gbdcs::gesture
