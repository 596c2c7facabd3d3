// The `sat` method: Akenine-Moller's triangle-box test ("Fast 3D Triangle-Box Overlap Testing", JGT 2001) in
// plain double precision, with the box translated to its centre as in the paper. It is fast and almost always
// right; rounding in the translation and the cross products can move a contact by a hair (issue 5 measures it).
#include <algorithm>
#include <cmath>

#include "vox/overlap.h"
#include "sphere_overlap.h"

namespace vox {

namespace {

bool planeBoxOverlap(const Vec3& normal, const Vec3& vert, const Vec3& half) {
  Vec3 vmin, vmax;
  for (int a = 0; a < 3; ++a) {
    const double v = vert[a];
    if (normal[a] > 0) {
      vmin.at(a) = -half[a] - v;
      vmax.at(a) = half[a] - v;
    } else {
      vmin.at(a) = half[a] - v;
      vmax.at(a) = -half[a] - v;
    }
  }
  if (dot(normal, vmin) > 0) return false;
  return dot(normal, vmax) >= 0;
}

}  // namespace

bool triangleBoxSat(const Triangle& t, const Box& box) {
  const Vec3 centre = (box.lo + box.hi) * 0.5;
  const Vec3 half = (box.hi - box.lo) * 0.5;
  const Vec3 v[3] = {t.v[0] - centre, t.v[1] - centre, t.v[2] - centre};
  const Vec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};

  // Nine axes: edge x unit axis.
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      // axis = e_i x unit_a has components (b, c) = (e_c, -e_b) up to sign.
      const double ab = e[i][c], ac = -e[i][b];
      double pmin = HUGE_VAL, pmax = -HUGE_VAL;
      for (const auto& p : v) {
        const double s = ab * p[b] + ac * p[c];
        pmin = std::min(pmin, s);
        pmax = std::max(pmax, s);
      }
      const double rad = std::fabs(ab) * half[b] + std::fabs(ac) * half[c];
      if (pmin > rad || pmax < -rad) return false;
    }
  }
  // Three box face normals.
  for (int a = 0; a < 3; ++a) {
    const double mn = std::min({v[0][a], v[1][a], v[2][a]});
    const double mx = std::max({v[0][a], v[1][a], v[2][a]});
    if (mn > half[a] || mx < -half[a]) return false;
  }
  // The triangle's plane.
  return planeBoxOverlap(cross(e[0], e[1]), v[0], half);
}

bool sphereBoxSat(const Sphere& s, const Box& box) { return sphereSurfaceMeetsBox<double>(s, box); }

}  // namespace vox
