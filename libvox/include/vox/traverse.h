// Walking a ray through the cells of a uniform grid (3D-DDA after Amanatides & Woo 1987), and the closest-hit and
// any-hit queries built on it.
//
// Robustness measures (docs/trace.md):
// - Every cell boundary is cellBoundary(), the voxelizer's formula; the t of the next boundary on each axis is
//   recomputed from it at every step ((b - o) / d, relative error a few ulps), never accumulated from tDelta.
// - Axes are stepped one at a time in the order of those t. When, at a step, the ray is within a small positional
//   tolerance of another axis's next boundary (a ray through an edge or corner, or close to one), the neighbouring
//   cells across those boundaries are visited too ("extra" cells), so rounding in the order of near-equal crossings
//   can never skip a cell the ray touches.
// - Direction components of +-0 never step; tiny ones (1e-30) give huge but finite boundary t; the walk is bounded
//   by nx + ny + nz + 3 steps, since every step moves one index one cell in the direction of travel.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vox/accel.h"
#include "vox/grid.h"
#include "vox/ray.h"

namespace vox {

struct WalkCell {
  std::array<uint32_t, 3> idx;
  double tEnter = 0, tExit = 0;
  // Conservative error bound on tExit, in ray parameter units: every cell after this one is entered no earlier
  // than tExit - exitSlack.
  double exitSlack = 0;
  int entryAxis = -1;  // axis whose boundary was crossed to enter; -1 when the walk starts inside the cell
  bool extra = false;  // a neighbour across a boundary the ray passes within tolerance of
};

class GridWalker {
 public:
  // Prepares the walk of `ray` over [ray.tMin, ray.tMax] through the grid of `bounds` and `dims`. A ray that misses
  // the grid, or has a zero or non-finite direction, yields no cell.
  GridWalker(const Box& bounds, const std::array<uint32_t, 3>& dims, const Ray& ray);

  // The next cell along the ray, in order of entry; false when the walk has left the grid or passed tMax.
  bool next(WalkCell& out) {
    if (queued_ > 0) {
      out = queue_[--queued_];
      return true;
    }
    if (done_) return false;
    out.idx = {uint32_t(idx_[0]), uint32_t(idx_[1]), uint32_t(idx_[2])};
    out.tEnter = tCur_;
    out.entryAxis = entryAxis_;
    out.extra = false;
    int m = 0;
    if (tNext_[1] < tNext_[m]) m = 1;
    if (tNext_[2] < tNext_[m]) m = 2;
    const double tm = tNext_[m];
    out.tExit = tm;
    out.exitSlack = tol_[m] + kRel * std::fabs(tm);
    step(m, tm, out);
    return true;
  }

  // Bound on the error of a primitive hit's t at parameter t (ray units), used to decide when the walk may stop.
  double hitSlack(double t) const { return hitSlack_ + 1e-9 * std::fabs(t); }
  uint64_t stepsTaken() const { return steps_; }

 private:
  static constexpr double kRel = 16 * std::numeric_limits<double>::epsilon();

  double boundary(int axis, int64_t i) const { return cellBoundary(bounds_, dims_, axis, i); }
  double nextT(int a) const {
    if (dir_[a] > 0) return (boundary(a, idx_[a] + 1) - org_[a]) / dir_[a];
    if (dir_[a] < 0) return (boundary(a, idx_[a]) - org_[a]) / dir_[a];
    return std::numeric_limits<double>::infinity();
  }
  // Is the ray, at parameter tm, within tolerance of axis a's next boundary?
  bool near(int a, double tm) const {
    return std::isfinite(tNext_[a]) && (tNext_[a] - tm) * std::fabs(dir_[a]) <= tolPos_[a] + kRel * std::fabs(tm * dir_[a]);
  }

  void step(int m, double tm, const WalkCell& from) {
    if (!(tm <= tHi_ + tol_[m] + kRel * std::fabs(tm)) || ++steps_ > maxSteps_) {
      done_ = true;
      return;
    }
    // Neighbours across boundaries that the ray passes within tolerance of at this step (edges and corners).
    int others[2], count = 0;
    for (int a = 0; a < 3; ++a)
      if (a != m && near(a, tm)) others[count++] = a;
    for (int subset = 1; subset < (1 << count); ++subset) {
      std::array<int64_t, 3> c = idx_;
      int lastAxis = -1;
      for (int s = 0; s < count; ++s)
        if (subset & (1 << s)) {
          c[others[s]] += step_[others[s]];
          lastAxis = others[s];
        }
      if (inside(c)) {
        WalkCell& e = queue_[queued_++];
        e = from;
        e.idx = {uint32_t(c[0]), uint32_t(c[1]), uint32_t(c[2])};
        e.tEnter = tm;
        e.entryAxis = lastAxis;
        e.extra = true;
      }
    }
    idx_[m] += step_[m];
    if (idx_[m] < 0 || idx_[m] >= int64_t(dims_[m])) {
      done_ = true;
      return;
    }
    tCur_ = tm;
    entryAxis_ = m;
    tNext_[m] = nextT(m);
  }
  bool inside(const std::array<int64_t, 3>& c) const {
    for (int a = 0; a < 3; ++a)
      if (c[a] < 0 || c[a] >= int64_t(dims_[a])) return false;
    return true;
  }

  Box bounds_;
  std::array<uint32_t, 3> dims_;
  double org_[3], dir_[3];
  std::array<int64_t, 3> idx_{0, 0, 0};
  int64_t step_[3] = {0, 0, 0};
  double tNext_[3];
  double tol_[3];     // positional tolerance of each axis in ray parameter units (infinite for a zero component)
  double tolPos_[3];  // positional tolerance of each axis in world units
  double tCur_ = 0, tHi_ = 0;
  double hitSlack_ = 0;
  int entryAxis_ = -1;
  bool done_ = true;
  uint64_t steps_ = 0, maxSteps_ = 0;
  WalkCell queue_[3];
  int queued_ = 0;
};

// Counters of one thread's tracing; summed over threads for --stats.
struct TraceStats {
  uint64_t rays = 0;
  uint64_t cells = 0;         // cells visited by walks (empty ones included)
  uint64_t tests = 0;         // ray-primitive intersection tests
  uint64_t mailboxSkips = 0;  // tests saved because the primitive was already tested by this ray

  TraceStats& operator+=(const TraceStats& o) {
    rays += o.rays;
    cells += o.cells;
    tests += o.tests;
    mailboxSkips += o.mailboxSkips;
    return *this;
  }
};

// The nearest hit of `ray` in [ray.tMin, ray.tMax] among all primitives, ties to the smaller id. With
// AccelKind::Grid the walk tests only the primitives of visited cells plus accel.alwaysTested; with
// AccelKind::None every primitive. Both give the same Hit when every primitive is in every cell its surface meets
// (exact, sat and bbox grids). `stats` may be null.
Hit traceRay(const Accel& accel, const Ray& ray, TraceStats* stats = nullptr);

// Whether anything is hit in [ray.tMin, ray.tMax] (shadow rays); also walks the grid for AccelKind::Grid.
bool occluded(const Accel& accel, const Ray& ray, TraceStats* stats = nullptr);

// The first occupied (or solid) cell along the ray, for the voxels mode. Independent of accel.kind.
struct CellHit {
  bool hit = false;
  double t = 0;                       // ray parameter where the cell is entered (ray.tMin when the ray starts in it)
  std::array<uint32_t, 3> idx{0, 0, 0};
  int entryAxis = -1;                 // as in WalkCell
  uint32_t primCount = 0;             // 0 for a solid cell
  bool solid = false;
};
CellHit firstOccupiedCell(const Accel& accel, const Ray& ray, TraceStats* stats = nullptr);

}  // namespace vox
