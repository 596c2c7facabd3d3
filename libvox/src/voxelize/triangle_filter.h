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

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

enum class FilterResult { Disjoint, Overlap, Unknown };

// Plain arrays rather than Vec3 so that the fixed-size loops below unroll into straight-line code.
struct TriangleFilter {
  double origin[3];             // v0
  double edges[3][3];           // v1 - v0, v2 - v1, v0 - v2
  double normal[3];             // (v1 - v0) x (v2 - v0)
  double normalErr[3];          // error bound of each normal component
  double triMin[3], triMax[3];  // exact bounding box of the vertices
  double edgeProj[3][3][2];     // [edge][axis] -> min, max of the triangle's projection
  double edgeProjErr[3][3];     // error bound of those projections
  // Which side of edge i's line (on the axis edges[i] x unit_a) the triangle lies: +1 above, -1 below, 0 unknown
  // (degenerate or too close to call). Schwarz and Seidel (2010): the triangle meets the box iff the box meets its
  // plane and, in each of the three axis projections, the box's bounding square and the 2D triangle overlap; in
  // 2D it suffices to check that the box is not entirely on the outer side of each edge. So an edge axis needs
  // testing on one side only, halving the work, whenever the side is certain.
  int edgeSide[3][3];
  bool usable = true;  // false: magnitudes outside the filter's range

  static constexpr double kU = DBL_EPSILON / 2;
  static constexpr double kTiny = 1e-300;
  static constexpr int kNext[3] = {1, 2, 0};
  static constexpr int kPrev[3] = {2, 0, 1};

  explicit TriangleFilter(const Triangle& t) {
    double v[3][3];
    for (int k = 0; k < 3; ++k) {
      v[k][0] = t.v[k].x;
      v[k][1] = t.v[k].y;
      v[k][2] = t.v[k].z;
    }
    double d[2][3];
    for (int a = 0; a < 3; ++a) {
      origin[a] = v[0][a];
      d[0][a] = v[1][a] - v[0][a];
      d[1][a] = v[2][a] - v[0][a];
      edges[0][a] = d[0][a];
      edges[1][a] = v[2][a] - v[1][a];
      edges[2][a] = v[0][a] - v[2][a];
      triMin[a] = std::min({v[0][a], v[1][a], v[2][a]});
      triMax[a] = std::max({v[0][a], v[1][a], v[2][a]});
      for (int k = 0; k < 3; ++k)
        if (std::fabs(v[k][a]) > 1e100) usable = false;
    }
    for (int a = 0; a < 3; ++a) {
      const int b = kNext[a], c = kPrev[a];
      normal[a] = d[0][b] * d[1][c] - d[0][c] * d[1][b];
      normalErr[a] = 8 * kU * (std::fabs(d[0][b] * d[1][c]) + std::fabs(d[0][c] * d[1][b])) + kTiny;
    }
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) {
        const int b = kNext[a], c = kPrev[a];
        // Projections of the three vertices (v0 at exactly 0) and their error bounds.
        double sv[3] = {0, 0, 0}, ev[3] = {0, kTiny, kTiny};
        for (int k = 0; k < 2; ++k) {
          const double t1 = edges[i][c] * d[k][b], t2 = edges[i][b] * d[k][c];
          sv[k + 1] = t1 - t2;
          ev[k + 1] = 8 * kU * (std::fabs(t1) + std::fabs(t2)) + kTiny;
        }
        edgeProj[i][a][0] = std::min({sv[0], sv[1], sv[2]});
        edgeProj[i][a][1] = std::max({sv[0], sv[1], sv[2]});
        edgeProjErr[i][a] = std::max(ev[1], ev[2]);
        const int e0 = i, e1 = (i + 1) % 3, third = (i + 2) % 3;
        const double edgeHi = std::max(sv[e0], sv[e1]), edgeLo = std::min(sv[e0], sv[e1]);
        const double sideErr = 2 * (ev[third] + std::max(ev[e0], ev[e1]));
        edgeSide[i][a] = sv[third] - edgeHi > sideErr ? 1 : (edgeLo - sv[third] > sideErr ? -1 : 0);
      }
  }

  // Per-cell error bounds depend on |corner - origin| only through an upper bound qMax[a] of it on each axis, valid
  // for every cell the caller will test (the voxelizer passes the extent of the triangle's cell range). Computing
  // them once per triangle keeps the per-cell test to a few multiply-adds per axis.
  double boxErr[3][3];  // [edge][axis]: total error bound of the comparison on that edge axis
  double normalBoxErr;
  int normalSel[3];      // per axis: 0 when the normal's box minimum uses the cell's low side, 1 for the high side
  int edgeSel[3][3][2];  // [edge][axis][b or c]: likewise for the edge axes' minimum

  void prepare(const double qMax[3]) {
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) {
        const int b = kNext[a], c = kPrev[a];
        const double cb = edges[i][c], cc = -edges[i][b];
        boxErr[i][a] = 8 * kU * (std::fabs(cb) * qMax[b] + std::fabs(cc) * qMax[c]) + kTiny + edgeProjErr[i][a];
        edgeSel[i][a][0] = cb >= 0 ? 0 : 1;
        edgeSel[i][a][1] = cc >= 0 ? 0 : 1;
      }
    double err = kTiny;
    for (int a = 0; a < 3; ++a) {
      err += qMax[a] * (normalErr[a] + 8 * kU * std::fabs(normal[a]));
      normalSel[a] = normal[a] >= 0 ? 0 : 1;
    }
    normalBoxErr = 2 * err;
  }

  // lo/hi: the closed cell. rel[0][a] = fl(lo[a] - origin[a]), rel[1][a] = fl(hi[a] - origin[a]), with
  // |rel| <= qMax of the last prepare().
  FilterResult test(const double lo[3], const double hi[3], const double rel[2][3]) const {
    // Box face normals: plain comparisons of inputs, no rounding at all.
    for (int a = 0; a < 3; ++a)
      if (triMin[a] > hi[a] || triMax[a] < lo[a]) return FilterResult::Disjoint;
    if (!usable) return FilterResult::Unknown;
    bool unknown = false;
    // The triangle's normal: the triangle projects to exactly 0; the box to [min, max] of n . (corner - origin),
    // reached at the corners the normal's signs select.
    {
      double boxMin = 0, boxMax = 0;
      for (int a = 0; a < 3; ++a) {
        boxMin += normal[a] * rel[normalSel[a]][a];
        boxMax += normal[a] * rel[1 - normalSel[a]][a];
      }
      const double err = normalBoxErr;
      if (boxMin > err || boxMax < -err) return FilterResult::Disjoint;
      unknown |= !(boxMin < -err && boxMax > err);
    }
    // Nine edge axes.
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) {
        const int b = kNext[a], c = kPrev[a];
        const double cb = edges[i][c], cc = -edges[i][b];
        const int sb = edgeSel[i][a][0], sc = edgeSel[i][a][1];
        const double err = boxErr[i][a];
        const int side = edgeSide[i][a];
        if (side >= 0) {  // the triangle is above the edge: the box must not lie entirely below
          const double boxMax = cb * rel[1 - sb][b] + cc * rel[1 - sc][c];
          const double triMinP = edgeProj[i][a][0];
          if (triMinP - boxMax > err) return FilterResult::Disjoint;
          unknown |= !(boxMax - triMinP > err);
        }
        if (side <= 0) {
          const double boxMin = cb * rel[sb][b] + cc * rel[sc][c];
          const double triMaxP = edgeProj[i][a][1];
          if (boxMin - triMaxP > err) return FilterResult::Disjoint;
          unknown |= !(triMaxP - boxMin > err);
        }
      }
    return unknown ? FilterResult::Unknown : FilterResult::Overlap;
  }

  // One box on its own: prepares the bounds for it, then tests.
  FilterResult test(const Box& box) {
    const double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
    double rel[2][3], qMax[3];
    for (int a = 0; a < 3; ++a) {
      rel[0][a] = lo[a] - origin[a];
      rel[1][a] = hi[a] - origin[a];
      qMax[a] = std::max(std::fabs(rel[0][a]), std::fabs(rel[1][a]));
    }
    prepare(qMax);
    return test(lo, hi, rel);
  }
};

}  // namespace vox
