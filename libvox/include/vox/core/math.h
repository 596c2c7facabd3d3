// Small double-precision vector and matrix types. World space throughout; no SIMD here on purpose:
// the exactness of the voxelizer depends on plain IEEE double arithmetic.
#pragma once

#include <array>
#include <cmath>

namespace vox {

struct Vec3 {
  double x = 0, y = 0, z = 0;

  double operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  double& at(int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(double s, const Vec3& a) { return a * s; }
inline Vec3 operator/(const Vec3& a, double s) { return {a.x / s, a.y / s, a.z / s}; }
inline Vec3 mul(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(const Vec3& a) {
  const double len = length(a);
  return len > 0 ? a / len : a;
}
inline Vec3 minVec(const Vec3& a, const Vec3& b) {
  return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)};
}
inline Vec3 maxVec(const Vec3& a, const Vec3& b) {
  return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)};
}
inline bool isFinite(const Vec3& a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// Axis-aligned box, closed: [lo, hi] on each axis.
struct Box {
  Vec3 lo, hi;
};

// Row-major 4x4 matrix acting on column vectors (p' = M p), as in the course's scene format and DESIGN.md.
struct Mat4 {
  std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};

  static Mat4 identity() { return {}; }
  bool isIdentity() const;
};

Mat4 operator*(const Mat4& a, const Mat4& b);
Vec3 transformPoint(const Mat4& m, const Vec3& p);
Vec3 transformVector(const Mat4& m, const Vec3& v);  // linear part only
Mat4 inverse(const Mat4& m);                         // throws vox::Error when singular
double linearDeterminant(const Mat4& m);             // of the upper-left 3x3 (linear) part
Mat4 transpose(const Mat4& m);
Mat4 translation(const Vec3& t);
Mat4 scaling(const Vec3& s);
Mat4 rotation(const Vec3& axis, double degrees);

}  // namespace vox
