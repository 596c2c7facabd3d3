// The floating-point filter of the exact triangle-box test: a separating-axis test (the 13 axes of Akenine-Moller
// 2001) evaluated in double relative to the triangle's first vertex, with a rigorous bound on the rounding error of
// every projection. Each axis answers "certainly separated", "certainly overlapping" or "cannot tell"; only the
// last sends the cell to CGAL.
//
// Error bound (u = 2^-53, standard model fl(a op b) = (a op b)(1 + d), |d| <= u): differences of inputs carry a
// relative error u; a projection s = a1 q1 + a2 q2 of rounded factors then errs by at most 4.01 u (|a1 q1| + |a2 q2|),
// and the normal's components n = d1 x d2 by 4.01 u times their terms' magnitudes, so n . q errs by at most
// sum |q_i| (err n_i + 4.01 u |n_i|) (1 + 4u). We use 8 u for 4.01 u, double again when comparing two projections,
// and add 1e-300 for underflow. Inputs whose magnitude exceeds 1e100 skip the filter (the bound could overflow).
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "vox/math.h"
#include "vox/scene.h"

namespace vox {

enum class FilterResult { Disjoint, Overlap, Unknown };

struct TriangleFilter {
  Vec3 origin;                 // v0
  Vec3 d[2];                   // v1 - v0, v2 - v0
  Vec3 edges[3];               // v1 - v0, v2 - v1, v0 - v2
  Vec3 normal, normalErr;      // d1 x d2 and its error bound per component
  Vec3 triMin, triMax;         // exact bounding box of the vertices
  double edgeProj[3][3][2];    // [edge][axis] -> min, max of the triangle's projection
  double edgeProjErr[3][3];    // error bound of those projections
  bool usable = true;          // false: magnitudes outside the filter's range

  static constexpr double kU = DBL_EPSILON / 2;
  static constexpr double kTiny = 1e-300;

  explicit TriangleFilter(const Triangle& t) {
    origin = t.v[0];
    d[0] = t.v[1] - t.v[0];
    d[1] = t.v[2] - t.v[0];
    edges[0] = d[0];
    edges[1] = t.v[2] - t.v[1];
    edges[2] = t.v[0] - t.v[2];
    triMin = minVec(minVec(t.v[0], t.v[1]), t.v[2]);
    triMax = maxVec(maxVec(t.v[0], t.v[1]), t.v[2]);
    for (const auto& v : t.v)
      for (int a = 0; a < 3; ++a)
        if (std::fabs(v[a]) > 1e100) usable = false;
    normal = cross(d[0], d[1]);
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      normalErr.at(a) = 8 * kU * (std::fabs(d[0][b] * d[1][c]) + std::fabs(d[0][c] * d[1][b])) + kTiny;
    }
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) {
        double mn = 0, mx = 0, err = 0;  // vertex 0 projects to exactly 0
        for (int k = 0; k < 2; ++k) {
          double m;
          const double s = edgeProjection(i, a, d[k], &m);
          mn = std::min(mn, s);
          mx = std::max(mx, s);
          err = std::max(err, 8 * kU * m + kTiny);
        }
        edgeProj[i][a][0] = mn;
        edgeProj[i][a][1] = mx;
        edgeProjErr[i][a] = err;
      }
  }

  // Projection of q (relative to the origin) onto edges[i] x unit_a, and the magnitude of its terms.
  double edgeProjection(int i, int a, const Vec3& q, double* magnitude) const {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const double t1 = edges[i][c] * q[b], t2 = edges[i][b] * q[c];
    *magnitude = std::fabs(t1) + std::fabs(t2);
    return t1 - t2;
  }

  // lo/hi: the closed cell. rel{Lo,Hi}: fl(lo - origin), fl(hi - origin), which the caller may cache per cell row.
  FilterResult test(const Vec3& lo, const Vec3& hi, const Vec3& relLo, const Vec3& relHi) const {
    // Box face normals: plain comparisons of inputs, no rounding at all.
    for (int a = 0; a < 3; ++a)
      if (triMin[a] > hi[a] || triMax[a] < lo[a]) return FilterResult::Disjoint;
    if (!usable) return FilterResult::Unknown;
    bool unknown = false;
    // Nine edge axes.
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const double cb = edges[i][c], cc = -edges[i][b];
        const double qb0 = cb * relLo[b], qb1 = cb * relHi[b];
        const double qc0 = cc * relLo[c], qc1 = cc * relHi[c];
        const double boxMin = std::min(qb0, qb1) + std::min(qc0, qc1);
        const double boxMax = std::max(qb0, qb1) + std::max(qc0, qc1);
        const double boxErr = 8 * kU * (std::max(std::fabs(qb0), std::fabs(qb1)) + std::max(std::fabs(qc0), std::fabs(qc1))) + kTiny;
        const double err = boxErr + edgeProjErr[i][a];
        const double triMinP = edgeProj[i][a][0], triMaxP = edgeProj[i][a][1];
        if (triMinP - boxMax > err || boxMin - triMaxP > err) return FilterResult::Disjoint;
        if (!(boxMax - triMinP > err && triMaxP - boxMin > err)) unknown = true;
      }
    // The triangle's normal: the triangle projects to exactly 0; the box to [min, max] of n . (corner - origin).
    double boxMin = 0, boxMax = 0, err = kTiny;
    for (int a = 0; a < 3; ++a) {
      const double p0 = normal[a] * relLo[a], p1 = normal[a] * relHi[a];
      boxMin += std::min(p0, p1);
      boxMax += std::max(p0, p1);
      const double q = std::max(std::fabs(relLo[a]), std::fabs(relHi[a]));
      err += q * (normalErr[a] + 8 * kU * std::fabs(normal[a]));
    }
    err *= 2;
    if (boxMin > err || boxMax < -err) return FilterResult::Disjoint;
    if (!(boxMin < -err && boxMax > err)) unknown = true;
    return unknown ? FilterResult::Unknown : FilterResult::Overlap;
  }
};

}  // namespace vox
