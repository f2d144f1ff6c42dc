// Small 3-D vector and rotation helpers for the hand model (private to sim/landmarks).
#pragma once

#include <array>
#include <cmath>
#include <numbers>

namespace gbdcs::sim::detail {

struct Vec3 {
  double x = 0;
  double y = 0;
  double z = 0;
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalized(Vec3 a) {
  const double n = norm(a);
  return n > 0 ? (1.0 / n) * a : a;
}

inline double deg_to_rad(double deg) { return deg * std::numbers::pi / 180.0; }
inline double rad_to_deg(double rad) { return rad * 180.0 / std::numbers::pi; }

// Row-major 3x3 matrix.
struct Mat3 {
  std::array<std::array<double, 3>, 3> m{};

  static Mat3 identity() { return {{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}}; }
  static Mat3 from_columns(Vec3 c0, Vec3 c1, Vec3 c2) {
    return {{{{c0.x, c1.x, c2.x}, {c0.y, c1.y, c2.y}, {c0.z, c1.z, c2.z}}}};
  }
  Mat3 transposed() const {
    Mat3 t;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) t.m[r][c] = m[c][r];
    return t;
  }
};

inline Vec3 operator*(const Mat3& a, Vec3 v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}
inline Mat3 operator*(const Mat3& a, const Mat3& b) {
  Mat3 p;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t k = 0; k < 3; ++k) p.m[r][c] += a.m[r][k] * b.m[k][c];
  return p;
}

// Rotations in the camera frame (x right, y down, z away): rot_z turns clockwise on the image.
inline Mat3 rot_x(double deg) {
  const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
  return {{{{1, 0, 0}, {0, c, -s}, {0, s, c}}}};
}
inline Mat3 rot_y(double deg) {
  const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
  return {{{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}}};
}
inline Mat3 rot_z(double deg) {
  const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
  return {{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}}};
}

// Palm frame -> camera frame with the palm facing the camera and the fingers up.
inline Mat3 palm_facing_camera() { return {{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}}; }

}  // namespace gbdcs::sim::detail
