// Independent exact references for the overlap tests, written for the tests only: the separating-axis theorem
// evaluated in exact rational arithmetic (CGAL::Gmpq), and the sphere surface test in rationals by the plain
// nearest/farthest-point formula. They share no code with libvox's exact method (which uses CGAL's Epick
// triangle-box predicate, a floating-point filter, and interval arithmetic).
#pragma once

#include <CGAL/Gmpq.h>

#include <algorithm>
#include <array>

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox::reference {

using Q = CGAL::Gmpq;
using QVec = std::array<Q, 3>;

inline QVec toQ(const Vec3& v) { return {Q(v.x), Q(v.y), Q(v.z)}; }

// Closed triangle vs closed box, exact: disjoint iff one of the 13 axes separates them. For degenerate triangles
// the zero axes never separate and the remaining ones are the separating axes of a segment or a point.
inline bool triangleMeetsBox(const Triangle& t, const Box& box) {
  const QVec v[3] = {toQ(t.v[0]), toQ(t.v[1]), toQ(t.v[2])};
  const QVec lo = toQ(box.lo), hi = toQ(box.hi);
  std::vector<QVec> axes = {{Q(1), Q(0), Q(0)}, {Q(0), Q(1), Q(0)}, {Q(0), Q(0), Q(1)}};
  QVec e[3];
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) e[i][a] = v[(i + 1) % 3][a] - v[i][a];
  auto crossQ = [](const QVec& a, const QVec& b) {
    return QVec{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) {
      QVec unit{Q(0), Q(0), Q(0)};
      unit[a] = Q(1);
      axes.push_back(crossQ(e[i], unit));
    }
  axes.push_back(crossQ(e[0], e[1]));
  for (const auto& ax : axes) {
    Q tMin, tMax;
    for (int k = 0; k < 3; ++k) {
      const Q p = ax[0] * v[k][0] + ax[1] * v[k][1] + ax[2] * v[k][2];
      if (k == 0 || p < tMin) tMin = p;
      if (k == 0 || p > tMax) tMax = p;
    }
    Q bMin(0), bMax(0);
    for (int a = 0; a < 3; ++a) {
      const Q p0 = ax[a] * lo[a], p1 = ax[a] * hi[a];
      bMin += p0 < p1 ? p0 : p1;
      bMax += p0 < p1 ? p1 : p0;
    }
    if (tMax < bMin || tMin > bMax) return false;
  }
  return true;
}

// Plain sphere (no transform): the surface meets the closed box iff dist(c, box)^2 <= r^2 <= max corner dist^2.
inline bool sphereSurfaceMeetsBox(const Vec3& center, double radius, const Box& box) {
  const QVec c = toQ(center), lo = toQ(box.lo), hi = toQ(box.hi);
  Q nearest(0), farthest(0);
  for (int a = 0; a < 3; ++a) {
    const Q clamped = c[a] < lo[a] ? lo[a] : (c[a] > hi[a] ? hi[a] : c[a]);
    nearest += (clamped - c[a]) * (clamped - c[a]);
    const Q dl = (lo[a] - c[a]) * (lo[a] - c[a]), dh = (hi[a] - c[a]) * (hi[a] - c[a]);
    farthest += dl > dh ? dl : dh;
  }
  const Q r2 = Q(radius) * Q(radius);
  return nearest <= r2 && r2 <= farthest;
}

}  // namespace vox::reference
