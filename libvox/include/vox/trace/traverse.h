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

// Which empty space the walk of an Accel jumps over (GridWalker::fastForward).
enum class EmptySkip : uint8_t { Blocks, Boxes };

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
  // With EmptySkip::Boxes only boxes of two or more blocks a side are jumped over (Accel::emptyShift above
  // blockShift; nothing without emptyShift): the walk of traceRay and occluded, whose steps cost less than a jump's
  // setup over a single block (issue 12).
  GridWalker(const Accel& accel, const Ray& ray, EmptySkip skip = EmptySkip::Blocks) {
    init(accel.boundaries, ray);
    if (accel.blockShift != 0 && !done_) {
      blockSlot_ = accel.blockSlot.data();
      shift_ = accel.blockShift;
      minSkip_ = skip == EmptySkip::Boxes ? accel.blockShift : 0;
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
      const uint32_t skip = skipShift();
      if (skip != 0) fastForward(skip);
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

  // The cells of repeated next() calls, the same ones in the same order with the same fields, passed to
  // `visit(const WalkCell&)`, which returns true to end the walk. The walk of traceRay and occluded (issue 12): the
  // state of the steps stays in registers, the stepped axis is a branch (predicted, so one step does not wait on the
  // comparisons of the last), and each axis's crossing after its next one is computed a step ahead, so that a step
  // only moves values. Rays with a component whose inverse is not a normal number (zero or tiny) take next().
  template <class Visit>
  void walk(Visit&& visit);

  // Called by walk()'s visitor on the cell it is visiting (not on an extra one): every cell of the box [lo, hi]
  // (inclusive indices, holding that cell) is known to hold nothing the ray must test, so the walk may jump to the
  // last cell of the box along the ray instead of stepping through it (Accel::cellBoxes, issue 27). The jump is
  // taken only where it is as robust as a step: not when the ray leaves the box near one of its edges or corners
  // (see fastForwardBox). Ignored for extra cells and by the next() path.
  void jumpOver(const std::array<uint32_t, 3>& lo, const std::array<uint32_t, 3>& hi) {
    for (int a = 0; a < 3; ++a) {
      jumpLo_[a] = lo[a];
      jumpHi_[a] = hi[a];
    }
    jump_ = true;
  }
  uint64_t jumpsTaken() const { return jumps_; }

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
  // Is the ray, at parameter tm, within tolerance of axis a's next boundary? Compared in ray parameter units (tol[a]
  // is tolPos[a] / |d_a|; the same bound as tolPos[a] in world units but for a few ulps of it). An infinite tNext is
  // never near: inf - tm exceeds any finite bound, and is NaN when tm is infinite too.
  bool near(int a, double tm) const { return nearAt(a, tNext_[a], tm, kRel * std::fabs(tm)); }
  bool nearAt(int a, double tNext, double tm, double relSlack) const { return tNext - tm <= ax_.tol[a] + relSlack; }
  // The crossing of axis a's boundary after the next one, from cell index i (nonzero step): the value nextT(a) takes
  // after the next step on a. The index is clamped into the table; where that changes it, that step leaves the grid
  // and the value is never used.
  double afterT(int a, int64_t i) const {
    const int64_t j = std::clamp<int64_t>(i + step_[a] + (step_[a] > 0 ? 1 : 0), 0, int64_t(dims_[a]));
    return ax_.crossing(a, bnd_[a][j], org_[a], dir_[a]);
  }
  // walk()'s copy of the state of the steps, in registers; `after` holds afterT of each axis.
  struct WalkState {
    int64_t idx[3];
    double t[3], after[3];
    double tCur;
    int entryAxis;
    uint64_t steps;
    bool checkBlock;
  };
  void saveState(const WalkState& w);
  void loadState(WalkState& w) const;
  // One step of walk() on axis M at parameter tm from `cell` (step() and next() in one); false when the walk ends.
  template <int M, class Visit>
  bool walkStep(Visit& visit, double tm, WalkCell& cell, WalkState& w);
  template <class Visit>
  bool visitExtras(Visit& visit, int m, double tm, const WalkCell& cell, const WalkState& w, bool n1, bool n2);

  // Shared by step() and walkStep(), which must agree bit for bit: is the boundary at tm (on axis m, relSlack =
  // kRel |tm|) past the end of the walk, and does index i, just stepped to on axis m, start a new block?
  bool pastEnd(int m, double tm, double relSlack) const { return !(tm <= tHi_ + ax_.tol[m] + relSlack); }
  bool entersBlock(int m, int64_t i) const {
    return (blockSlot_ != nullptr) & ((i & blockMask()) == (step_[m] > 0 ? 0 : blockMask()));
  }

  void step(int m, double tm, const WalkCell& from) {
    if (pastEnd(m, tm, kRel * std::fabs(tm)) || ++steps_ > maxSteps_) {
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
    checkBlock_ = entersBlock(m, idx_[m]);
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
  // On entering a block: the shift of the empty box to jump over (see fastForward), or 0 to walk on.
  uint32_t skipShift() const {
    const uint32_t skip = emptyShift_ != nullptr ? emptyShift_[blockIndex()] : blockEmpty() ? shift_ : 0;
    return skip > minSkip_ ? skip : 0;
  }
  void fastForward(uint32_t shift);
  // Moves the walk to the cell holding the ray just before it leaves the box [lo, hi] (inclusive cell indices,
  // holding the current cell), as the steps would, but for the cells in between; nothing when the ray leaves the
  // box within tolerance of two of its faces at once or never leaves it.
  void fastForwardBox(const int64_t lo[3], const int64_t hi[3]);
  // walk()'s side of jumpOver: the jump from the state `w`; false (w unchanged) when it would not move the walk.
  bool takeJump(WalkState& w);
  // Boxes whose far face lies more cells away on an axis than this are crossed by advanceBySearch, not cell by cell.
  static constexpr int64_t kMaxLoopCells = 32;
  void advanceBySearch(int a, int64_t far, double T);

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
  uint32_t minSkip_ = 0;  // boxes of 2^minSkip_ cells a side or smaller are walked (EmptySkip)
  // A jump asked for by the visitor (jumpOver).
  bool jump_ = false;
  int64_t jumpLo_[3] = {0, 0, 0}, jumpHi_[3] = {0, 0, 0};
  uint64_t jumps_ = 0;
};

template <int M, class Visit>
inline bool GridWalker::walkStep(Visit& visit, double tm, WalkCell& cell, WalkState& w) {
  const double relSlack = kRel * std::fabs(tm);
  cell.tExit = tm;
  cell.exitSlack = ax_.tol[M] + relSlack;
  if (visit(static_cast<const WalkCell&>(cell))) return false;
  if (jump_) [[unlikely]] {
    jump_ = false;
    if (takeJump(w)) return true;
  }
  if (pastEnd(M, tm, relSlack) || ++w.steps > maxSteps_) return false;
  constexpr int A1 = M == 0, A2 = 2 - (M == 2);
  const bool n1 = nearAt(A1, w.t[A1], tm, relSlack), n2 = nearAt(A2, w.t[A2], tm, relSlack);
  if (n1 | n2) [[unlikely]]
    if (!visitExtras(visit, M, tm, cell, w, n1, n2)) return false;
  w.idx[M] += step_[M];
  if (uint64_t(w.idx[M]) >= dims_[M]) return false;
  w.checkBlock = entersBlock(M, w.idx[M]);
  w.tCur = tm;
  w.entryAxis = M;
  w.t[M] = w.after[M];
  w.after[M] = afterT(M, w.idx[M]);
  return true;
}

// The rare paths of walk() go through the members and next()'s own functions.
inline void GridWalker::saveState(const WalkState& w) {
  for (int a = 0; a < 3; ++a) {
    idx_[a] = w.idx[a];
    tNext_[a] = w.t[a];
  }
  tCur_ = w.tCur;
  entryAxis_ = w.entryAxis;
  steps_ = w.steps;
}
inline void GridWalker::loadState(WalkState& w) const {
  for (int a = 0; a < 3; ++a) {
    w.idx[a] = idx_[a];
    w.t[a] = tNext_[a];
    w.after[a] = afterT(a, idx_[a]);
  }
  w.tCur = tCur_;
  w.entryAxis = entryAxis_;
  w.steps = steps_;
}

template <class Visit>
inline bool GridWalker::visitExtras(Visit& visit, int m, double tm, const WalkCell& cell, const WalkState& w, bool n1,
                                    bool n2) {
  saveState(w);
  const WalkCell from = cell;  // a copy, so that `cell` itself never escapes the registers
  queueExtras(m, tm, from, n1, n2);
  while (queued_ > 0) {
    if (visit(static_cast<const WalkCell&>(queue_[--queued_]))) return false;
    jump_ = false;  // an extra cell's box says nothing of the cells the walk goes on through
  }
  return true;
}

inline bool GridWalker::takeJump(WalkState& w) {
  saveState(w);
  const uint64_t before = steps_;
  fastForwardBox(jumpLo_, jumpHi_);
  if (steps_ == before) return false;
  ++jumps_;
  loadState(w);
  w.checkBlock = blockSlot_ != nullptr;  // the jump may have entered a new block
  return true;
}

template <class Visit>
inline void GridWalker::walk(Visit&& visit) {
  WalkCell cell;
  if (done_ || queued_ > 0 || ax_.divide[0] || ax_.divide[1] || ax_.divide[2]) {
    while (next(cell)) {
      if (visit(static_cast<const WalkCell&>(cell))) return;
      jump_ = false;  // next() has already stepped past the cell: no jump from there
    }
    return;
  }
  WalkState w;
  loadState(w);
  w.checkBlock = checkBlock_;
  cell.extra = false;
  for (;;) {
    if (w.checkBlock) [[unlikely]] {
      w.checkBlock = false;
      saveState(w);
      const uint32_t skip = skipShift();
      if (skip != 0) {
        fastForward(skip);
        loadState(w);
      }
    }
    cell.idx = {uint32_t(w.idx[0]), uint32_t(w.idx[1]), uint32_t(w.idx[2])};
    cell.tEnter = w.tCur;
    cell.entryAxis = w.entryAxis;
    // The axis of the nearest next boundary, first of equals (as next()).
    const bool b01 = w.t[1] < w.t[0];
    const double t01 = b01 ? w.t[1] : w.t[0];
    bool more;
    if (w.t[2] < t01)
      more = walkStep<2>(visit, w.t[2], cell, w);
    else if (b01)
      more = walkStep<1>(visit, w.t[1], cell, w);
    else
      more = walkStep<0>(visit, w.t[0], cell, w);
    if (!more) break;
  }
  saveState(w);
  done_ = true;
}

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
