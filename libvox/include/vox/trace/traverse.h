// Walking a ray through the cells of a uniform grid (3D-DDA after Amanatides & Woo 1987), and the closest-hit and
// any-hit queries built on it.
//
// Robustness measures (docs/trace.md):
// - Every cell boundary is cellBoundary(), the voxelizer's formula (read from tables holding its values); the t of
//   the next boundary on each axis is recomputed from it at every step ((b - o) * (1 / d), relative error a few
//   ulps), never accumulated from tDelta.
// - Axes are stepped one at a time in the order of those t. When, at a step, the ray is within a small positional
//   tolerance of another axis's next boundary (a ray through an edge or corner, or close to one), the neighbouring
//   cells across those boundaries are visited too ("extra" cells), so rounding in the order of near-equal crossings
//   can never skip a cell the ray touches.
// - Direction components of +-0 never step; tiny ones (1e-30) give huge but finite boundary t; the walk is bounded
//   by nx + ny + nz + 3 steps, since every step moves one index one cell in the direction of travel.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "vox/trace/accel.h"
#include "vox/core/grid.h"
#include "vox/trace/ray.h"

namespace vox {

// Tolerances of the walk (docs/trace.md), shared by the single-ray walker and the packet traversal.
inline constexpr double kWalkRel = 16 * std::numeric_limits<double>::epsilon();  // relative slack on any t
// Fraction of a cell by which boundaries are treated as fuzzy: rays passing this close to an edge or corner also
// visit the cells across it. Costs an extra cell visit about once per million crossings.
inline constexpr double kCellSlack = 1e-6;

// Positional tolerance on axis a, in world units, for coordinates up to `coord` in magnitude: a fraction of a cell
// plus the rounding of coordinates that large (the grid's own included).
inline double positionTolerance(const CellBoundaries& cells, int a, double coord) {
  return kCellSlack * cells.cellSize[a] +
         64 * std::numeric_limits<double>::epsilon() * (std::fabs(coord) + cells.magnitude[a]);
}
// Bound on the error of a primitive hit's position, world units, for a ray from `origin`; divided by a direction
// component no larger than the largest it is a bound in ray parameter units (RayAxes::hitSlack).
inline double hitSlackLength(const CellBoundaries& cells, const Vec3& origin) {
  double scale = 0;
  for (int a = 0; a < 3; ++a) scale = std::max(scale, std::fabs(origin[a]) + cells.magnitude[a]);
  return kCellSlack * cells.minCell + 64 * std::numeric_limits<double>::epsilon() * scale;
}
// Bound on the error of a primitive hit's t at parameter t, from the part independent of t: what decides when a
// walk may stop.
inline double hitSlackAt(double hitSlack, double t) { return hitSlack + 1e-9 * std::fabs(t); }

// The per-axis constants of one ray's walk.
struct RayAxes {
  double inv[3];     // 1 / d
  bool divide[3];    // 1 / d is not a normal number: divide by d instead of multiplying by inv
  double tolPos[3];  // positional tolerance of each axis in world units
  double tol[3];     // the same in ray parameter units (0 for a zero component)
  double hitSlack;   // bound on the error of a primitive hit's t, without the part relative to t

  // The parameter at which the ray crosses the plane x_a = b: (b - o) * (1 / d) when 1 / d is a normal number (a
  // multiplication instead of a division per step; error at most 2 ulps more than the quotient, far inside kWalkRel),
  // else (b - o) / d. Only for a nonzero d.
  double crossing(int a, double b, double o, double d) const { return divide[a] ? (b - o) / d : (b - o) * inv[a]; }
  double hitSlackAt(double t) const { return vox::hitSlackAt(hitSlack, t); }
};
RayAxes rayAxes(const CellBoundaries& cells, const Ray& ray);

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
  // Prepares the walk of `ray` over [ray.tMin, ray.tMax] through the grid of `cells` (which must outlive the walker;
  // Accel::boundaries). A ray that misses the grid, or has a zero or non-finite direction, yields no cell.
  GridWalker(const CellBoundaries& cells, const Ray& ray) { init(cells, ray); }
  // The walk of traceRay and friends: through accel.boundaries, and skipping the cells of empty blocks of the
  // two-level table (Accel::blockSlot) in one jump each, or of the largest empty aligned box of blocks holding one
  // (Accel::emptyShift; see fastForward); cells in empty blocks may therefore not be reported. `accel` must outlive
  // the walker.
  GridWalker(const Accel& accel, const Ray& ray) {
    init(accel.boundaries, ray);
    if (accel.blockShift != 0 && !done_) {
      blockSlot_ = accel.blockSlot.data();
      shift_ = accel.blockShift;
      blockDims_[0] = accel.blockDims[0];
      blockDims_[1] = accel.blockDims[1];
      emptyShift_ = accel.emptyShift.empty() ? nullptr : accel.emptyShift.data();
      checkBlock_ = true;
    }
  }
  // The same walk through the grid of `bounds` and `dims`; builds the boundary tables first (allocates: for tests
  // and one-off walks, not for tracing many rays).
  GridWalker(const Box& bounds, const std::array<uint32_t, 3>& dims, const Ray& ray)
      : owned_(std::make_unique<CellBoundaries>(makeCellBoundaries(bounds, dims))) {
    init(*owned_, ray);
  }

  // The next cell along the ray, in order of entry; false when the walk has left the grid or passed tMax.
  bool next(WalkCell& out) {
    if (queued_ > 0) {
      out = queue_[--queued_];
      return true;
    }
    if (done_) return false;
    if (checkBlock_) [[unlikely]] {
      checkBlock_ = false;
      if (emptyShift_ != nullptr) {
        const uint32_t skip = emptyShift_[blockIndex()];
        if (skip != 0) fastForward(skip);
      } else if (blockEmpty()) {
        fastForward(shift_);
      }
    }
    out.idx = {uint32_t(idx_[0]), uint32_t(idx_[1]), uint32_t(idx_[2])};
    out.tEnter = tCur_;
    out.entryAxis = entryAxis_;
    out.extra = false;
    // The axis of the nearest next boundary (first of equals), without branches: which axis wins is data
    // dependent, and mispredicted branches cost more than the comparisons.
    // GCC turns the selects of an int into a branch, so m is formed from the comparison bits (b2 ? 2 : b01).
    const double t0 = tNext_[0], t1 = tNext_[1], t2 = tNext_[2];
    const int b01 = t1 < t0;
    const double t01 = t1 < t0 ? t1 : t0;
    const int b2 = t2 < t01;
    const int m = b01 + 2 * b2 - (b01 & b2);
    const double tm = t2 < t01 ? t2 : t01;
    out.tExit = tm;
    out.exitSlack = ax_.tol[m] + kRel * std::fabs(tm);
    step(m, tm, out);
    return true;
  }

  // Bound on the error of a primitive hit's t at parameter t (ray units), used to decide when the walk may stop.
  double hitSlack(double t) const { return ax_.hitSlackAt(t); }
  uint64_t stepsTaken() const { return steps_; }

 private:
  static constexpr double kRel = kWalkRel;

  void init(const CellBoundaries& cells, const Ray& ray);
  double nextT(int a) const {
    if (step_[a] == 0) return std::numeric_limits<double>::infinity();
    const double b = bnd_[a][idx_[a] + (step_[a] > 0 ? 1 : 0)];
    return ax_.crossing(a, b, org_[a], dir_[a]);
  }
  // Is the ray, at parameter tm, within tolerance of axis a's next boundary?
  // Both conditions evaluated (no short circuit): the second is harmless for an infinite tNext_ and the branch
  // would be mispredicted.
  bool near(int a, double tm) const {
    return std::isfinite(tNext_[a]) &
           ((tNext_[a] - tm) * std::fabs(dir_[a]) <= ax_.tolPos[a] + kRel * std::fabs(tm * dir_[a]));
  }

  void step(int m, double tm, const WalkCell& from) {
    if (!(tm <= tHi_ + ax_.tol[m] + kRel * std::fabs(tm)) || ++steps_ > maxSteps_) {
      done_ = true;
      return;
    }
    // Neighbours across boundaries that the ray passes within tolerance of at this step (edges and corners).
    const int a1 = m == 0, a2 = 2 - (m == 2);
    const bool n1 = near(a1, tm), n2 = near(a2, tm);
    if (n1 | n2) [[unlikely]]
      queueExtras(m, tm, from, n1, n2);
    idx_[m] += step_[m];
    if (uint64_t(idx_[m]) >= dims_[m]) {  // also catches -1
      done_ = true;
      return;
    }
    // Entering a new block: look whether it is empty before reporting its first cell.
    checkBlock_ = (blockSlot_ != nullptr) & ((idx_[m] & blockMask()) == (step_[m] > 0 ? 0 : blockMask()));
    tCur_ = tm;
    entryAxis_ = m;
    tNext_[m] = nextT(m);
  }
  void queueExtras(int m, double tm, const WalkCell& from, bool n1, bool n2);
  int64_t blockMask() const { return (int64_t(1) << shift_) - 1; }
  uint64_t blockIndex() const {
    const uint64_t bx = uint64_t(idx_[0]) >> shift_, by = uint64_t(idx_[1]) >> shift_, bz = uint64_t(idx_[2]) >> shift_;
    return bx + blockDims_[0] * (by + blockDims_[1] * bz);
  }
  bool blockEmpty() const { return blockSlot_[blockIndex()] == kEmptyCell; }
  void fastForward(uint32_t shift);

  std::unique_ptr<CellBoundaries> owned_;  // the tables, when the walker built them itself
  const double* bnd_[3] = {nullptr, nullptr, nullptr};
  uint64_t dims_[3] = {0, 0, 0};
  double org_[3], dir_[3];
  RayAxes ax_{};
  int64_t idx_[3] = {0, 0, 0};
  int64_t step_[3] = {0, 0, 0};
  double tNext_[3];
  double tCur_ = 0, tHi_ = 0;
  int entryAxis_ = -1;
  bool done_ = true;
  uint64_t steps_ = 0, maxSteps_ = 0;
  WalkCell queue_[3];
  int queued_ = 0;
  // Empty-block skipping (Accel constructor only).
  const uint32_t* blockSlot_ = nullptr;
  uint32_t shift_ = 0;
  uint64_t blockDims_[2] = {0, 0};
  const uint8_t* emptyShift_ = nullptr;  // Accel::emptyShift, when built
  bool checkBlock_ = false;
};

// Counters of one thread's tracing; summed over threads for --stats.
struct TraceStats {
  uint64_t rays = 0;
  uint64_t cells = 0;         // cells visited by walks (empty ones included)
  uint64_t tests = 0;         // ray-primitive intersection tests
  uint64_t mailboxSkips = 0;  // tests saved because the primitive was already tested by this ray
  uint64_t filtered = 0;      // triangles the float filter rejected without a test (trace/float_filter.h)

  TraceStats& operator+=(const TraceStats& o) {
    rays += o.rays;
    cells += o.cells;
    tests += o.tests;
    mailboxSkips += o.mailboxSkips;
    filtered += o.filtered;
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
  double t = 0;  // ray parameter where the cell is entered (ray.tMin when the ray starts in it)
  std::array<uint32_t, 3> idx{0, 0, 0};
  int entryAxis = -1;      // as in WalkCell
  uint32_t primCount = 0;  // 0 for a solid cell
  bool solid = false;
};
CellHit firstOccupiedCell(const Accel& accel, const Ray& ray, TraceStats* stats = nullptr);

}  // namespace vox
