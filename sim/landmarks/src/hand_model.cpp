// Forward kinematics of the hand and its projection into the image.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "geometry.hpp"
#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::sim {
namespace {

using contracts::Point3;
using detail::Mat3;
using detail::Vec3;
namespace lm = contracts;

// Palm frame (mm) of a right hand: x toward the thumb, y wrist -> middle knuckle, z out of
// the palm. Knuckle positions and bone lengths from adult anthropometry (middle finger
// MCP-to-tip 93 mm, wrist-to-MCP 88 mm); the index and pinky knuckles sit a little palmar
// of the middle one, which is the transverse arch of the hand.
struct FingerModel {
  Vec3 mcp;
  double base_angle_deg;  // in-plane direction at zero spread, + toward the thumb
  double spread_gain;     // how much of spread_deg this finger takes
  std::array<double, 3> bone_mm;
};
constexpr std::array<FingerModel, kFingerCount> kFingers{{
    {{22, 84, 3}, 4, 0.8, {40, 23, 20}},
    {{0, 88, 0}, 0, 0.1, {45, 27, 21}},
    {{-18, 83, 2}, -4, -0.5, {42, 26, 21}},
    {{-34, 74, 6}, -9, -1.0, {33, 18, 19}},
}};
constexpr Vec3 kThumbCmc{24, 22, 8};
constexpr std::array<double, 3> kThumbBoneMm{42, 32, 25};  // metacarpal, proximal, distal
constexpr double kThumbBaseAngleDeg = 12;  // in-plane angle of a fully adducted thumb
constexpr Vec3 kPalmCentre{0, 44, 0};      // the point a Placement puts at its centre

Point3 to_point(Vec3 v) { return {v.x, v.y, v.z}; }
Vec3 to_vec(const Point3& p) { return {p.x, p.y, p.z}; }

double lerp(double a, double b, double t) { return a * (1 - t) + b * t; }  // exact at 0 and 1
double lerp_angle(double a, double b, double t) {
  const double d = std::remainder(b - a, 360.0);  // the short way round
  return a + d * t;
}

bool finite(double v) { return std::isfinite(v); }

void check_placement(const Placement& p) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("Placement: " + what);
  };
  for (double v : {p.center_x, p.center_y, p.size, p.roll_deg, p.yaw_deg, p.pitch_deg,
                   p.aspect_ratio, p.presence}) {
    if (!finite(v)) fail("every field must be finite");
  }
  if (p.size <= 0) fail("size must be > 0 (hand length / frame height)");
  if (std::abs(p.yaw_deg) > 40) fail("|yaw_deg| must be <= 40");
  if (std::abs(p.pitch_deg) > 40) fail("|pitch_deg| must be <= 40");
  if (p.aspect_ratio <= 0) fail("aspect_ratio must be > 0 (width / height)");
  if (p.presence < 0 || p.presence > 1) fail("presence must be in [0, 1]");
}

}  // namespace

std::array<Point3, lm::kLandmarkCount> hand_points_mm(const HandPose& pose) {
  std::array<Point3, lm::kLandmarkCount> out{};
  const Vec3 palm_normal{0, 0, 1};
  out[lm::kWrist] = {0, 0, 0};

  for (std::size_t f = 0; f < kFingerCount; ++f) {
    const FingerModel& model = kFingers[f];
    const FingerPose& joints = pose.fingers[f];
    // Fingers converge as they flex: a fist is narrower than a spread hand.
    const double flex_gain = std::max(0.0, std::cos(detail::deg_to_rad(joints.mcp_deg)));
    const double abduction =
        model.base_angle_deg + model.spread_gain * pose.spread_deg * (0.3 + 0.7 * flex_gain);
    const double a = detail::deg_to_rad(abduction);
    const Vec3 base{std::sin(a), std::cos(a), 0};

    const std::size_t first = lm::kIndexMcp + 4 * f;
    Vec3 p = model.mcp;
    out[first] = to_point(p);
    double phi = 0;
    const std::array<double, 3> flexion{joints.mcp_deg, joints.pip_deg, joints.dip_deg};
    for (std::size_t b = 0; b < 3; ++b) {
      phi += detail::deg_to_rad(flexion[b]);
      p = p + model.bone_mm[b] * (std::cos(phi) * base + std::sin(phi) * palm_normal);
      out[first + 1 + b] = to_point(p);
    }
  }

  // Thumb: the metacarpal leaves the CMC joint at an in-plane angle (abduction) and tilts
  // toward the palm (flexion); the MCP and IP joints then curl it in a plane that faces
  // partly across the palm and partly into it, because the thumb is pronated relative to the
  // fingers. The more it opposes, the more that plane turns into the palm.
  const ThumbPose& thumb = pose.thumb;
  const double alpha = detail::deg_to_rad(kThumbBaseAngleDeg + thumb.cmc_abduction_deg);
  const double beta = detail::deg_to_rad(thumb.cmc_flexion_deg);
  const Vec3 in_plane{std::sin(alpha), std::cos(alpha), 0};
  const Vec3 metacarpal = std::cos(beta) * in_plane + std::sin(beta) * palm_normal;
  const Vec3 across{-std::cos(alpha), std::sin(alpha), 0};  // toward the fingers
  const double gamma = detail::deg_to_rad(20 + 0.4 * thumb.cmc_flexion_deg);
  Vec3 curl = std::cos(gamma) * across + std::sin(gamma) * palm_normal;
  curl = detail::normalized(curl - dot(curl, metacarpal) * metacarpal);

  Vec3 p = kThumbCmc;
  out[lm::kThumbCmc] = to_point(p);
  p = p + kThumbBoneMm[0] * metacarpal;
  out[lm::kThumbMcp] = to_point(p);
  double phi = detail::deg_to_rad(thumb.mcp_deg);
  p = p + kThumbBoneMm[1] * (std::cos(phi) * metacarpal + std::sin(phi) * curl);
  out[lm::kThumbIp] = to_point(p);
  phi += detail::deg_to_rad(thumb.ip_deg);
  p = p + kThumbBoneMm[2] * (std::cos(phi) * metacarpal + std::sin(phi) * curl);
  out[lm::kThumbTip] = to_point(p);
  return out;
}

HandJointAngles joint_angles(const HandPose& pose) {
  HandJointAngles out;
  for (std::size_t f = 0; f < kFingerCount; ++f) {
    const double flex_gain = std::max(0.0, std::cos(detail::deg_to_rad(pose.fingers[f].mcp_deg)));
    out.finger_abduction_deg[f] = kFingers[f].base_angle_deg + kFingers[f].spread_gain *
                                                                   pose.spread_deg *
                                                                   (0.3 + 0.7 * flex_gain);
  }
  const ThumbPose& thumb = pose.thumb;
  const double alpha = detail::deg_to_rad(kThumbBaseAngleDeg + thumb.cmc_abduction_deg);
  const double beta = detail::deg_to_rad(thumb.cmc_flexion_deg);
  const Vec3 palm_normal{0, 0, 1};
  const Vec3 in_plane{std::sin(alpha), std::cos(alpha), 0};
  const Vec3 metacarpal = std::cos(beta) * in_plane + std::sin(beta) * palm_normal;
  const Vec3 across{-std::cos(alpha), std::sin(alpha), 0};
  const double gamma = detail::deg_to_rad(20 + 0.4 * thumb.cmc_flexion_deg);
  Vec3 curl = std::cos(gamma) * across + std::sin(gamma) * palm_normal;
  curl = detail::normalized(curl - dot(curl, metacarpal) * metacarpal);
  // The metacarpal's frame after the two base rotations: x is the flexion axis.
  const Vec3 x1{std::cos(alpha), -std::sin(alpha), 0};
  const Vec3 z1 = cross(x1, metacarpal);
  out.thumb_abduction_deg = kThumbBaseAngleDeg + thumb.cmc_abduction_deg;
  out.thumb_flexion_deg = thumb.cmc_flexion_deg;
  out.thumb_twist_deg = detail::rad_to_deg(std::atan2(dot(curl, x1), dot(curl, z1)));
  return out;
}

contracts::Landmarks synthesize(const HandPose& pose, const Placement& placement) {
  check_placement(placement);
  const HandOrientation& o = pose.orientation;
  const Mat3 attitude = detail::rot_z(o.roll_deg) * detail::rot_x(o.pitch_deg) *
                        detail::rot_y(o.yaw_deg) * detail::palm_facing_camera();
  const Mat3 aim = detail::rot_z(o.aim_deg);
  const Mat3 place = detail::rot_z(placement.roll_deg) * detail::rot_x(placement.pitch_deg) *
                     detail::rot_y(placement.yaw_deg);
  const bool mirror = placement.handedness == contracts::Handedness::kLeft;

  const auto points_mm = hand_points_mm(pose);
  // Normalised units per mm: y by the frame height, x and z by the frame width.
  const double per_mm_y = placement.size / kHandLengthMm;
  const double per_mm_x = per_mm_y / placement.aspect_ratio;

  contracts::Landmarks out;
  out.handedness = placement.handedness;
  out.score = placement.presence;
  std::array<Vec3, lm::kLandmarkCount> camera{};
  for (std::size_t i = 0; i < lm::kLandmarkCount; ++i) {
    Vec3 v = attitude * (to_vec(points_mm[i]) - kPalmCentre);
    if (mirror) v.x = -v.x;
    camera[i] = place * (aim * v);
  }
  const double wrist_z = camera[lm::kWrist].z;
  for (std::size_t i = 0; i < lm::kLandmarkCount; ++i) {
    out.points[i] = {placement.center_x + camera[i].x * per_mm_x,
                     placement.center_y + camera[i].y * per_mm_y,
                     (camera[i].z - wrist_z) * per_mm_x};
  }
  return out;
}

void add_landmark_noise(contracts::Landmarks& hand, double sigma_fraction, double size,
                        std::mt19937& rng) {
  // Placement::size is a fraction of the frame height; x and z use the width, but the
  // difference is well inside what the noise is meant to model, so one sigma is used.
  const double sigma = sigma_fraction * size;
  for (auto& p : hand.points) {
    p.x += gaussian(rng, sigma);
    p.y += gaussian(rng, sigma);
    p.z += gaussian(rng, 2 * sigma);
  }
}

HandPose blend(const HandPose& from, const HandPose& to, double t) {
  t = std::clamp(t, 0.0, 1.0);
  HandPose out;
  out.thumb = {lerp(from.thumb.cmc_abduction_deg, to.thumb.cmc_abduction_deg, t),
               lerp(from.thumb.cmc_flexion_deg, to.thumb.cmc_flexion_deg, t),
               lerp(from.thumb.mcp_deg, to.thumb.mcp_deg, t),
               lerp(from.thumb.ip_deg, to.thumb.ip_deg, t)};
  for (std::size_t f = 0; f < kFingerCount; ++f) {
    out.fingers[f] = {lerp(from.fingers[f].mcp_deg, to.fingers[f].mcp_deg, t),
                      lerp(from.fingers[f].pip_deg, to.fingers[f].pip_deg, t),
                      lerp(from.fingers[f].dip_deg, to.fingers[f].dip_deg, t)};
  }
  out.spread_deg = lerp(from.spread_deg, to.spread_deg, t);
  const HandOrientation& a = from.orientation;
  const HandOrientation& b = to.orientation;
  out.orientation = {lerp_angle(a.yaw_deg, b.yaw_deg, t), lerp_angle(a.pitch_deg, b.pitch_deg, t),
                     lerp_angle(a.roll_deg, b.roll_deg, t), lerp_angle(a.aim_deg, b.aim_deg, t)};
  return out;
}

double uniform(std::mt19937& rng, double lo, double hi) {
  // 53 random bits from two draws: the mt19937 stream itself is specified by the standard.
  const auto high = static_cast<std::uint64_t>(rng()) >> 5;  // 27 bits
  const auto low = static_cast<std::uint64_t>(rng()) >> 6;   // 26 bits
  const double u = static_cast<double>((high << 26) | low) / 9007199254740992.0;  // 2^53
  return lo + (hi - lo) * u;
}

double gaussian(std::mt19937& rng, double sigma) {
  // Box-Muller; clipped so a rare draw cannot turn one pose into another.
  const double u1 = uniform(rng, 1e-12, 1.0);
  const double u2 = uniform(rng, 0.0, 1.0);
  const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  return sigma * std::clamp(z, -2.5, 2.5);
}

}  // namespace gbdcs::sim
