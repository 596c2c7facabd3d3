// The textbook grid walk, as a yardstick for issue 12's speed goal: how fast can any 3D-DDA over our cells be?
// Amanatides & Woo (1987) as the course teaches it: the start cell by a clamped floor, the next crossing accumulated
// from tDelta, the nearest crossing's axis stepped, the walk stopped as soon as the best hit lies before the next
// crossing. The cells' triangles go through the same float filter, mailbox and double test as vox::traceRay's.
//
// It is NOT robust, and nothing but bench_trace uses it: it has none of the walk's tolerances (no extra cells near
// edges and corners, no slack in the stop rule or the start cell, crossings that drift by accumulation) and none of
// its empty-space jumps, so it can miss hits that vox::traceRay finds; bench_trace counts how many of its results
// differ from ours. What it measures is the cost of the walk itself, without the price of exactness.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "trace/float_filter.h"
#include "trace/mailbox.h"
#include "vox/trace/accel.h"
#include "vox/trace/ray.h"

namespace textbook {

// The walk's state: the current cell, the next crossing and the crossing spacing of each axis.
struct Walk {
  int64_t idx[3], step[3], n[3];
  double tNext[3], tDelta[3], tEnd;
};

// The walk of `ray` from where it enters the grid box; false when it misses the box.
inline bool start(const vox::CellBoundaries& cb, const vox::Ray& ray, Walk& w) {
  double t0 = ray.tMin, t1 = ray.tMax;
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    if (d == 0) {
      if (o < cb.b[a].front() || o > cb.b[a].back()) return false;
      continue;
    }
    double ta = (cb.b[a].front() - o) / d, tb = (cb.b[a].back() - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return false;
  w.tEnd = t1;
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    w.n[a] = cb.dims[a];
    const double g = ((d == 0 ? o : o + t0 * d) - cb.b[a][0]) * cb.cellsPerUnit[a];
    w.idx[a] = int64_t(std::clamp(g, 0.0, double(w.n[a] - 1)));
    w.step[a] = d > 0 ? 1 : -1;
    w.tNext[a] = d == 0 ? vox::kInfinity : (cb.b[a][w.idx[a] + (d > 0)] - o) / d;
    w.tDelta[a] = d == 0 ? 0 : cb.cellSize[a] / std::fabs(d);
  }
  return true;
}

// Steps to the next cell; false when the walk leaves the grid or its nearest crossing lies beyond `tStop`.
inline bool advance(Walk& w, double tStop) {
  const double* t = w.tNext;
  const int m = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
  if (!(t[m] <= std::min(tStop, w.tEnd))) return false;
  w.idx[m] += w.step[m];
  if (uint64_t(w.idx[m]) >= uint64_t(w.n[m])) return false;
  w.tNext[m] += w.tDelta[m];
  return true;
}

// The nearest hit (AnyHit: any hit) of `ray` among the triangles of the cells the textbook walk visits. The accel
// must have float cells with block tables (Accel::floatCells.slots) and only triangles, as the bench scenes do.
template <bool AnyHit>
vox::Hit trace(const vox::Accel& accel, const vox::Ray& ray) {
  vox::Hit best;
  vox::filter::FilterRay fr{};
  Walk w;
  if (!vox::filter::prepareFilterRay(accel.floatCells, ray, fr) || !start(accel.boundaries, ray, w)) return best;
  vox::Mailbox<64> mailbox;
  do {
    const vox::FloatCells::Cell cell = accel.floatCell(uint32_t(w.idx[0]), uint32_t(w.idx[1]), uint32_t(w.idx[2]));
    const vox::TriangleGroup4* g = accel.floatCells.groups.data() + cell.first;
    for (uint32_t k = 0; k < cell.count; k += 4, ++g)
      for (uint32_t maybe = vox::filter::maybeHits(*g, fr, std::min<uint32_t>(cell.count - k, 4)); maybe != 0;
           maybe &= maybe - 1) {
        const uint32_t id = g->id[__builtin_ctz(maybe)];
        double t;
        if (!mailbox.seen(id) && vox::intersectTriangle(accel.triangles[id], ray, t) && vox::closer(t, id, best)) {
          best = {t, id};
          if (AnyHit) return best;
        }
      }
  } while (advance(w, best.t));
  return best;
}

// The walk alone: the same cells as trace() visits up to parameter `tStop` (the ray's nearest hit), each cell looked
// up, no triangle tested. Returns the sum of the cells' triangle counts, so that the lookups are not optimized away.
inline uint64_t walkOnly(const vox::Accel& accel, const vox::Ray& ray, double tStop) {
  Walk w;
  if (!start(accel.boundaries, ray, w)) return 0;
  uint64_t sum = 0;
  do sum += accel.floatCell(uint32_t(w.idx[0]), uint32_t(w.idx[1]), uint32_t(w.idx[2])).count;
  while (advance(w, tStop));
  return sum;
}

}  // namespace textbook
