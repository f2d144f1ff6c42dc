// The pose library: each gesture of the vocabulary and each non-deliberate pose, with
// natural variation, aimed in the image where the pose is defined by a direction.
#include <algorithm>
#include <cmath>
#include <utility>

#include "geometry.hpp"
#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::sim {
namespace {

using contracts::GestureType;
using detail::Mat3;
using detail::Vec3;
namespace lm = contracts;

constexpr std::array<std::pair<PoseName, std::string_view>, 16> kPoseNames{{
    {PoseName::kOpenPalm, "OPEN_PALM"},
    {PoseName::kFist, "FIST"},
    {PoseName::kThumbUp, "THUMB_UP"},
    {PoseName::kThumbDown, "THUMB_DOWN"},
    {PoseName::kPointLeft, "POINT_LEFT"},
    {PoseName::kPointRight, "POINT_RIGHT"},
    {PoseName::kPointUp, "POINT_UP"},
    {PoseName::kVictory, "VICTORY"},
    {PoseName::kILoveYou, "I_LOVE_YOU"},
    {PoseName::kFourFingers, "FOUR_FINGERS"},
    {PoseName::kCall, "CALL"},
    {PoseName::kRock, "ROCK"},
    {PoseName::kOkSign, "OK_SIGN"},
    {PoseName::kPinch, "PINCH"},
    {PoseName::kHalfClosed, "HALF_CLOSED"},
    {PoseName::kRelaxed, "RELAXED"},
}};

// Nominal joint angles (deg) and how much they vary from hand to hand and moment to moment.
struct FingerSpec {
  double mcp, pip, dip, sigma;
};
constexpr FingerSpec kExtended{3, 5, 5, 3.5};
constexpr FingerSpec kFolded{85, 100, 60, 5};     // folded under a thumb (THUMB_UP, CALL, ...)
// A clenched fist: the composite flexion of a normal full fist, about 260 deg (MCP 90, PIP
// 100, DIP 70); the folded fingers of the thumb poses are a little looser (245 deg).
constexpr FingerSpec kClenched{90, 100, 70, 5};
constexpr FingerSpec kHeld{80, 98, 55, 5};        // folded, held down by the thumb
// The resting hand (RELAXED): flexion grows from the index to the little finger, the
// "cascade" of a hand at rest (MCP 30-45, PIP 40-55, DIP 15-22).
constexpr std::array<FingerSpec, 4> kRestCascade{
    {{30, 40, 15, 4}, {35, 45, 18, 4}, {40, 50, 20, 4}, {45, 55, 22, 4}}};
constexpr FingerSpec kHalfCurl{45, 55, 30, 5};

struct ThumbSpec {
  double abduction, flexion, mcp, ip, sigma;
};
constexpr ThumbSpec kThumbOut{40, 10, 5, 5, 4};
constexpr ThumbSpec kThumbWide{48, 8, 3, 3, 4};        // I_LOVE_YOU, CALL
constexpr ThumbSpec kThumbStraightUp{15, 12, 0, 0, 4};  // THUMB_UP / THUMB_DOWN
constexpr ThumbSpec kThumbOverFingers{5, 35, 45, 35, 4};  // fist, pointing, victory, rock
constexpr ThumbSpec kThumbAcrossPalm{0, 55, 50, 30, 4};   // FOUR_FINGERS
constexpr ThumbSpec kThumbRelaxed{25, 20, 15, 15, 4};
constexpr ThumbSpec kThumbHalf{15, 30, 30, 25, 4};

FingerPose draw(const FingerSpec& s, std::mt19937& rng) {
  return {s.mcp + gaussian(rng, s.sigma), std::max(-5.0, s.pip + gaussian(rng, s.sigma)),
          std::max(-5.0, s.dip + gaussian(rng, s.sigma))};
}

ThumbPose draw(const ThumbSpec& s, std::mt19937& rng) {
  return {s.abduction + gaussian(rng, s.sigma), s.flexion + gaussian(rng, s.sigma),
          s.mcp + gaussian(rng, s.sigma), std::max(-10.0, s.ip + gaussian(rng, s.sigma))};
}

HandPose make(const ThumbSpec& thumb, const std::array<const FingerSpec*, 4>& fingers,
              double spread_deg, std::mt19937& rng) {
  HandPose pose;
  pose.thumb = draw(thumb, rng);
  for (std::size_t f = 0; f < kFingerCount; ++f) pose.fingers[f] = draw(*fingers[f], rng);
  pose.spread_deg = std::max(0.0, spread_deg + gaussian(rng, 4));
  return pose;
}

// A shape pose faces the camera (or shows its back), fingers up, turned a little.
void face_camera(HandPose& pose, double back_probability, std::mt19937& rng) {
  const bool back = uniform(rng, 0, 1) < back_probability;
  pose.orientation = {(back ? 180.0 : 0.0) + gaussian(rng, 10), gaussian(rng, 10),
                      gaussian(rng, 8), 0};
}

// Turns the hand so that `digit` (MCP -> tip) points exactly up before the aim, with the
// palm normal turned `twist_deg` about that axis away from facing the camera; the aim then
// turns up into the wanted image direction. Decomposes into HandOrientation's Euler angles.
void aim_digit(HandPose& pose, lm::LandmarkIndex mcp, lm::LandmarkIndex tip, double twist_deg,
               double aim_deg) {
  const auto pts = hand_points_mm(pose);
  const Vec3 d = detail::normalized(Vec3{pts[tip].x - pts[mcp].x, pts[tip].y - pts[mcp].y,
                                         pts[tip].z - pts[mcp].z});
  const Vec3 n{0, 0, 1};
  const Vec3 e2 = detail::normalized(n - dot(n, d) * d);
  const Mat3 from = Mat3::from_columns(d, e2, cross(d, e2));

  const Vec3 up{0, -1, 0};
  const Vec3 facing = detail::rot_y(twist_deg) * Vec3{0, 0, -1};
  const Mat3 to = Mat3::from_columns(up, facing, cross(up, facing));

  const Mat3 m = to * from.transposed() * detail::palm_facing_camera().transposed();
  const double pitch = std::asin(std::clamp(m.m[2][1], -1.0, 1.0));
  const double yaw = std::atan2(-m.m[2][0], m.m[2][2]);
  const double roll = std::atan2(-m.m[0][1], m.m[1][1]);
  pose.orientation = {detail::rad_to_deg(yaw), detail::rad_to_deg(pitch),
                      detail::rad_to_deg(roll), aim_deg};
}

void point(HandPose& pose, double aim_deg, std::mt19937& rng) {
  double twist = uniform(rng, -60, 60);
  if (uniform(rng, 0, 1) < 0.5) twist += 180;  // back of the hand toward the camera
  aim_digit(pose, lm::kIndexMcp, lm::kIndexTip, twist, aim_deg + gaussian(rng, 5));
}

void thumb_aim(HandPose& pose, double aim_deg, std::mt19937& rng) {
  aim_digit(pose, lm::kThumbMcp, lm::kThumbTip, uniform(rng, -90, 90),
            aim_deg + gaussian(rng, 5));
}

// Brings the thumb tip onto the index fingertip (OK sign, pinch) by a pattern search over
// the thumb joints and the index's MCP and PIP within their ranges (the two digits meet
// halfway, as they do), then leaves a millimetre or two of slack.
void touch_index_with_thumb(HandPose& pose, std::mt19937& rng) {
  auto gap = [&pose] {
    const auto p = hand_points_mm(pose);
    const double dx = p[lm::kThumbTip].x - p[lm::kIndexTip].x;
    const double dy = p[lm::kThumbTip].y - p[lm::kIndexTip].y;
    const double dz = p[lm::kThumbTip].z - p[lm::kIndexTip].z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  };
  std::array<double*, 6> joints{&pose.thumb.cmc_abduction_deg, &pose.thumb.cmc_flexion_deg,
                                &pose.thumb.mcp_deg,           &pose.thumb.ip_deg,
                                &pose.fingers[0].mcp_deg,      &pose.fingers[0].pip_deg};
  constexpr std::array<std::pair<double, double>, 6> kRange{
      {{0, 60}, {0, 70}, {0, 70}, {-10, 80}, {20, 75}, {30, 100}}};
  double best = gap();
  for (double step = 8; step > 0.25; step /= 2) {
    bool improved = true;
    while (improved) {
      improved = false;
      for (std::size_t j = 0; j < joints.size(); ++j) {
        for (double sign : {-1.0, 1.0}) {
          const double old = *joints[j];
          *joints[j] = std::clamp(old + sign * step, kRange[j].first, kRange[j].second);
          const double g = gap();
          if (g < best - 1e-9) {
            best = g;
            improved = true;
          } else {
            *joints[j] = old;
          }
        }
      }
    }
  }
  pose.thumb.ip_deg += gaussian(rng, 2);
}

}  // namespace

std::string_view to_string(PoseName p) {
  for (const auto& [pose, name] : kPoseNames) {
    if (pose == p) return name;
  }
  return "?";
}

std::optional<PoseName> pose_from_string(std::string_view s) {
  for (const auto& [pose, name] : kPoseNames) {
    if (name == s) return pose;
  }
  return std::nullopt;
}

std::optional<GestureType> gesture_of(PoseName p) {
  switch (p) {
    case PoseName::kOpenPalm: return GestureType::kOpenPalm;
    case PoseName::kFist: return GestureType::kFist;
    case PoseName::kThumbUp: return GestureType::kThumbUp;
    case PoseName::kThumbDown: return GestureType::kThumbDown;
    case PoseName::kPointLeft: return GestureType::kPointLeft;
    case PoseName::kPointRight: return GestureType::kPointRight;
    case PoseName::kPointUp: return GestureType::kPointUp;
    case PoseName::kVictory: return GestureType::kVictory;
    case PoseName::kILoveYou: return GestureType::kILoveYou;
    default: return std::nullopt;
  }
}

bool is_direction_pose(PoseName p) {
  return p == PoseName::kThumbUp || p == PoseName::kThumbDown || p == PoseName::kPointLeft ||
         p == PoseName::kPointRight || p == PoseName::kPointUp;
}

HandPose pose_for(PoseName name, std::mt19937& rng) {
  const FingerSpec* ext = &kExtended;
  const FingerSpec* fold = &kFolded;
  const FingerSpec* held = &kHeld;
  HandPose pose;
  switch (name) {
    case PoseName::kOpenPalm:
      pose = make(kThumbOut, {ext, ext, ext, ext}, 18, rng);
      face_camera(pose, 0.2, rng);
      break;
    case PoseName::kFist:
      pose = make(kThumbOverFingers, {&kClenched, &kClenched, &kClenched, &kClenched}, 3, rng);
      face_camera(pose, 0.5, rng);
      break;
    case PoseName::kThumbUp:
    case PoseName::kThumbDown:
      pose = make(kThumbStraightUp, {fold, fold, fold, fold}, 3, rng);
      thumb_aim(pose, name == PoseName::kThumbUp ? 0 : 180, rng);
      break;
    case PoseName::kPointLeft:
    case PoseName::kPointRight:
    case PoseName::kPointUp:
      pose = make(kThumbOverFingers, {ext, held, held, held}, 5, rng);
      point(pose, name == PoseName::kPointLeft ? -90 : name == PoseName::kPointRight ? 90 : 0,
            rng);
      break;
    case PoseName::kVictory:
      pose = make(kThumbOverFingers, {ext, ext, held, held}, 28, rng);
      face_camera(pose, 0.3, rng);
      break;
    case PoseName::kILoveYou:
      pose = make(kThumbWide, {ext, fold, fold, ext}, 18, rng);
      face_camera(pose, 0.2, rng);
      break;
    case PoseName::kFourFingers:
      pose = make(kThumbAcrossPalm, {ext, ext, ext, ext}, 12, rng);
      face_camera(pose, 0.2, rng);
      break;
    case PoseName::kCall:
      pose = make(kThumbWide, {fold, fold, fold, ext}, 15, rng);
      face_camera(pose, 0.4, rng);
      break;
    case PoseName::kRock:
      pose = make(kThumbOverFingers, {ext, held, held, ext}, 18, rng);
      face_camera(pose, 0.4, rng);
      break;
    case PoseName::kOkSign: {
      static constexpr FingerSpec kOkIndex{40, 60, 35, 4};
      pose = make(kThumbRelaxed, {&kOkIndex, ext, ext, ext}, 12, rng);
      touch_index_with_thumb(pose, rng);
      face_camera(pose, 0.2, rng);
      break;
    }
    case PoseName::kPinch: {
      static constexpr FingerSpec kPinchIndex{35, 45, 20, 4};
      pose = make(kThumbRelaxed, {&kPinchIndex, &kHalfCurl, &kHalfCurl, &kHalfCurl}, 8, rng);
      touch_index_with_thumb(pose, rng);
      face_camera(pose, 0.3, rng);
      break;
    }
    case PoseName::kHalfClosed:
      pose = make(kThumbHalf, {&kHalfCurl, &kHalfCurl, &kHalfCurl, &kHalfCurl}, 8, rng);
      face_camera(pose, 0.3, rng);
      break;
    case PoseName::kRelaxed:
      pose = make(kThumbRelaxed, {&kRestCascade[0], &kRestCascade[1], &kRestCascade[2],
                                  &kRestCascade[3]},
                  8, rng);
      face_camera(pose, 0.3, rng);
      break;
  }
  return pose;
}

}  // namespace gbdcs::sim
