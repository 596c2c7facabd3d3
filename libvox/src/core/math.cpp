#include "vox/core/math.h"

#include "vox/core/error.h"

namespace vox {

bool Mat4::isIdentity() const {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (m[r][c] != (r == c ? 1.0 : 0.0)) return false;
  return true;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += a.m[r][k] * b.m[k][c];
      out.m[r][c] = sum;
    }
  return out;
}

Vec3 transformPoint(const Mat4& t, const Vec3& p) {
  const auto& m = t.m;
  return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
          m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
}

Vec3 transformVector(const Mat4& t, const Vec3& v) {
  const auto& m = t.m;
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Mat4 transpose(const Mat4& a) {
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.m[r][c] = a.m[c][r];
  return out;
}

// Gauss-Jordan with partial pivoting; scene transforms are small and well conditioned in practice.
Mat4 inverse(const Mat4& a) {
  double w[4][8];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      w[r][c] = a.m[r][c];
      w[r][c + 4] = r == c ? 1 : 0;
    }
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::fabs(w[r][col]) > std::fabs(w[pivot][col])) pivot = r;
    if (w[pivot][col] == 0 || !std::isfinite(w[pivot][col])) fail<InputError>("singular transform matrix");
    if (pivot != col)
      for (int c = 0; c < 8; ++c) std::swap(w[pivot][c], w[col][c]);
    const double inv = 1.0 / w[col][col];
    for (int c = 0; c < 8; ++c) w[col][c] *= inv;
    for (int r = 0; r < 4; ++r) {
      if (r == col) continue;
      const double f = w[r][col];
      if (f == 0) continue;
      for (int c = 0; c < 8; ++c) w[r][c] -= f * w[col][c];
    }
  }
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.m[r][c] = w[r][c + 4];
  return out;
}

Mat4 translation(const Vec3& t) {
  Mat4 out;
  out.m[0][3] = t.x;
  out.m[1][3] = t.y;
  out.m[2][3] = t.z;
  return out;
}

Mat4 scaling(const Vec3& s) {
  Mat4 out;
  out.m[0][0] = s.x;
  out.m[1][1] = s.y;
  out.m[2][2] = s.z;
  return out;
}

// Rodrigues' formula; exact zeros and ones for multiples of 90 degrees so axis-aligned scenes stay axis-aligned.
Mat4 rotation(const Vec3& axis, double degrees) {
  const Vec3 a = normalize(axis);
  const double turns = degrees / 90.0;
  double c, s;
  // fmod keeps the quarter turn exact for any whole number of turns; an int cast overflows past 2^31 turns.
  if (std::isfinite(turns) && turns == std::round(turns)) {
    const double quarter = std::fmod(turns, 4.0);
    const int q = int(quarter < 0 ? quarter + 4 : quarter);
    const double cs[4] = {1, 0, -1, 0}, sn[4] = {0, 1, 0, -1};
    c = cs[q];
    s = sn[q];
  } else {
    const double rad = degrees * M_PI / 180.0;
    c = std::cos(rad);
    s = std::sin(rad);
  }
  const double t = 1 - c;
  Mat4 out;
  out.m[0][0] = t * a.x * a.x + c;
  out.m[0][1] = t * a.x * a.y - s * a.z;
  out.m[0][2] = t * a.x * a.z + s * a.y;
  out.m[1][0] = t * a.x * a.y + s * a.z;
  out.m[1][1] = t * a.y * a.y + c;
  out.m[1][2] = t * a.y * a.z - s * a.x;
  out.m[2][0] = t * a.x * a.z - s * a.y;
  out.m[2][1] = t * a.y * a.z + s * a.x;
  out.m[2][2] = t * a.z * a.z + c;
  return out;
}

double linearDeterminant(const Mat4& t) {
  const auto& m = t.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

}  // namespace vox
