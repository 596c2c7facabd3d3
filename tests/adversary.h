// Random and adversarial triangle/box pairs for the overlap tests and the sat search (bench/sat_search.cpp):
// cells of random grids with boundaries from the one formula, and points on their faces, edges and corners or one
// ulp beside them; triangles in cell planes, collinear, points, tiny ones; at several scales and offsets.
#pragma once

#include <array>
#include <cmath>
#include <random>

#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox::testing {

struct Case {
  double scale, offset;
};
inline const Case kCases[] = {{1.0, 0.0}, {1e-6, 0.0}, {1.0, 1e7}, {1e-3, -1e7}, {1e6, 3.0}};

// A box of a random grid cell with boundaries from the one formula, and points chosen on its faces, edges and
// corners or nearby, so that contacts are common.
class Adversary {
 public:
  Adversary(uint32_t seed, Case c) : rng_(seed), case_(c) {
    for (auto& n : dims_) n = 1 + rng_() % 7;
    bounds_ = {{c.offset - c.scale, c.offset - c.scale * 0.5, c.offset},
               {c.offset + c.scale, c.offset + c.scale, c.offset + 2 * c.scale}};
  }

  Box cell() {
    const uint32_t ijk[3] = {uint32_t(rng_() % dims_[0]), uint32_t(rng_() % dims_[1]), uint32_t(rng_() % dims_[2])};
    Box b;
    for (int a = 0; a < 3; ++a) {
      b.lo.at(a) = cellBoundary(bounds_, dims_, a, ijk[a]);
      b.hi.at(a) = cellBoundary(bounds_, dims_, a, ijk[a] + 1);
    }
    return b;
  }

  // A coordinate on axis a: a cell boundary, one ulp beside one, or a random value.
  double coord(int a) {
    const int64_t i = int64_t(rng_() % (dims_[a] + 1));
    const double b = cellBoundary(bounds_, dims_, a, i);
    switch (rng_() % 5) {
      case 0:
      case 1:
        return b;
      case 2:
        return std::nextafter(b, HUGE_VAL);
      case 3:
        return std::nextafter(b, -HUGE_VAL);
      default: {
        std::uniform_real_distribution<double> u(bounds_.lo[a] - 0.2 * case_.scale, bounds_.hi[a] + 0.2 * case_.scale);
        return u(rng_);
      }
    }
  }
  Vec3 point() { return {coord(0), coord(1), coord(2)}; }

  Triangle triangle() {
    Triangle t;
    const int kind = int(rng_() % 6);
    t.v[0] = point();
    t.v[1] = point();
    t.v[2] = point();
    if (kind == 1) {  // in a cell plane
      const int a = int(rng_() % 3);
      const double p = cellBoundary(bounds_, dims_, a, int64_t(rng_() % (dims_[a] + 1)));
      for (auto& v : t.v) v.at(a) = p;
    } else if (kind == 2) {  // collinear: on a cell edge line, or a repeated vertex
      t.v[2] = (rng_() % 2) ? t.v[1] : t.v[0];
    } else if (kind == 3) {  // a point
      t.v[1] = t.v[2] = t.v[0];
    } else if (kind == 4) {  // tiny, near a corner
      const double eps = case_.scale * 1e-9;
      t.v[1] = t.v[0] + Vec3{eps, 0, eps};
      t.v[2] = t.v[0] + Vec3{0, eps, -eps};
    }
    return t;
  }

  std::mt19937& rng() { return rng_; }
  const Box& bounds() const { return bounds_; }
  const std::array<uint32_t, 3>& dims() const { return dims_; }

 private:
  std::mt19937 rng_;
  Case case_;
  std::array<uint32_t, 3> dims_;
  Box bounds_;
};

}  // namespace vox::testing
