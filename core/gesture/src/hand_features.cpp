#include "gbdcs/gesture/hand_features.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace gbdcs::gesture {
namespace {

namespace lm = contracts;

struct V3 {
  double x = 0;
  double y = 0;
  double z = 0;
};
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 scaled(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }

double rad_to_deg(double r) { return r * 180.0 / std::numbers::pi; }

// Angle between two vectors (deg); 0 when either has no length, so a collapsed bone reads as
// straight rather than as NaN.
double angle_deg(V3 a, V3 b) {
  const double la = length(a), lb = length(b);
  if (la <= 0 || lb <= 0) return 0;
  return rad_to_deg(std::acos(std::clamp(dot(a, b) / (la * lb), -1.0, 1.0)));
}

// Image direction, 0 = up, clockwise positive (y grows downward).
double direction_deg(V3 v) { return rad_to_deg(std::atan2(v.x, -v.y)); }

double in_plane(V3 v) {
  const double l = length(v);
  return l > 0 ? std::hypot(v.x, v.y) / l : 0;
}

}  // namespace

double angle_between_directions_deg(double a_deg, double b_deg) {
  return std::abs(std::remainder(a_deg - b_deg, 360.0));
}

HandFeatures extract_features(const contracts::Landmarks& hand, double aspect_ratio,
                              double depth_weight) {
  HandFeatures f;
  if (!std::isfinite(aspect_ratio) || aspect_ratio <= 0) return f;
  std::array<V3, lm::kLandmarkCount> p{};
  for (std::size_t i = 0; i < lm::kLandmarkCount; ++i) {
    const auto& q = hand.points[i];
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) return f;
    // x and z are in frame widths, y in frame heights: bring all to frame heights.
    p[i] = {q.x * aspect_ratio, q.y, q.z * aspect_ratio * depth_weight};
  }

  const V3 wrist = p[lm::kWrist];
  double palm = 0;
  for (auto k : {lm::kIndexMcp, lm::kMiddleMcp, lm::kRingMcp, lm::kPinkyMcp}) {
    palm += length(p[k] - wrist) / 4;
  }
  // A palm narrower than a thousandth of the frame carries no shape; nor does a collapsed one.
  const double knuckle_width = length(p[lm::kIndexMcp] - p[lm::kPinkyMcp]);
  if (!std::isfinite(palm) || !(palm > 1e-3) || !(knuckle_width > 0.1 * palm)) return f;
  f.palm_size = palm;

  // Long baselines only (wrist->knuckle, knuckle->tip, CMC->MCP): angles between the short
  // distal bones are dominated by landmark jitter.
  for (std::size_t finger = 0; finger < 4; ++finger) {
    const std::size_t mcp = lm::kIndexMcp + 4 * finger;
    f.finger_curl_deg[finger] = angle_deg(p[mcp] - wrist, p[mcp + 3] - p[mcp]);
  }

  // Palm axes from the knuckles: `along` toward the fingers, `radial` toward the index side,
  // which is the thumb side for either hand, so the thumb's lateral position needs no label.
  const V3 knuckles = p[lm::kIndexMcp] - p[lm::kPinkyMcp];
  const V3 along_raw = p[lm::kMiddleMcp] - wrist;
  const V3 along = scaled(along_raw, 1.0 / length(along_raw));
  const V3 radial_raw = knuckles - scaled(along, dot(knuckles, along));
  const double radial_length = length(radial_raw);
  if (!(radial_length > 0.05 * palm)) return f;
  const V3 radial = scaled(radial_raw, 1.0 / radial_length);

  const V3 thumb_tip = p[lm::kThumbTip] - wrist;
  f.thumb_bend_deg =
      angle_deg(p[lm::kThumbMcp] - p[lm::kThumbCmc], p[lm::kThumbTip] - p[lm::kThumbMcp]);
  f.thumb_lateral = dot(thumb_tip, radial) / palm;
  f.thumb_reach = length(p[lm::kThumbTip] - p[lm::kPinkyMcp]) / palm;

  const V3 index = p[lm::kIndexTip] - p[lm::kIndexMcp];
  const V3 middle = p[lm::kMiddleTip] - p[lm::kMiddleMcp];
  f.index_middle_spread_deg = angle_deg(index, middle);
  f.index_direction_deg = direction_deg(index);
  f.index_in_plane = in_plane(index);
  const V3 thumb = p[lm::kThumbTip] - p[lm::kThumbMcp];
  f.thumb_direction_deg = direction_deg(thumb);
  f.thumb_in_plane = in_plane(thumb);
  f.valid = true;
  return f;
}

}  // namespace gbdcs::gesture
