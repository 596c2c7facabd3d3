#include "vox/trace/traverse.h"

#include <algorithm>

#include "trace/float_filter.h"
#include "trace/mailbox.h"

namespace vox {

namespace {

constexpr double kRel = kWalkRel;

// Largest i in [0, n-1] with b[i] <= c (c below the grid gives 0, above gives n-1). The multiplication only guesses;
// the comparisons with the table (the values of cellBoundary) decide. The guess is clamped to [0, n - 1] before it is
// truncated, which is then its floor: std::floor is a library call without SSE4.1 (4% of an incoherent ray).
int64_t cellBelow(const CellBoundaries& cb, int a, double c) {
  const double* b = cb.b[a].data();
  const int64_t n = cb.dims[a];
  double guess = (c - b[0]) * cb.cellsPerUnit[a];
  if (!(guess >= 0)) guess = 0;
  if (guess > double(n - 1)) guess = double(n - 1);
  int64_t i = int64_t(guess);
  while (i > 0 && b[i] > c) --i;
  while (i < n - 1 && b[i + 1] <= c) ++i;
  return i;
}

// Smallest i in [0, n-1] with b[i+1] >= c.
int64_t cellAbove(const CellBoundaries& cb, int a, double c) {
  const double* b = cb.b[a].data();
  const int64_t n = cb.dims[a];
  int64_t i = cellBelow(cb, a, c);
  while (i > 0 && b[i] >= c) --i;
  while (i < n - 1 && b[i + 1] < c) ++i;
  return i;
}

}  // namespace

RayAxes rayAxes(const CellBoundaries& cells, const Ray& ray) {
  RayAxes ax;
  for (int a = 0; a < 3; ++a) {
    const double d = ray.direction[a];
    ax.tolPos[a] = positionTolerance(cells, a, ray.origin[a]);
    ax.inv[a] = 1.0 / d;
    ax.divide[a] = !std::isnormal(ax.inv[a]);
    ax.tol[a] = d == 0 ? 0 : ax.divide[a] ? ax.tolPos[a] / std::fabs(d) : ax.tolPos[a] * std::fabs(ax.inv[a]);
  }
  // Divided by the largest component rather than the length (no square root): at most sqrt(3) times larger, and a
  // larger slack only makes the stop rule more careful.
  const Vec3& d = ray.direction;
  const double dirMax = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  ax.hitSlack = hitSlackLength(cells, ray.origin) / dirMax;
  return ax;
}

namespace {

// The parameters [tLo, tHi] within which `ray` (finite, nonzero direction, restricted to [tMin, tMax]) can be inside
// the closed grid box, widened by the tolerances; `entryAxis` is the axis whose slab sets tLo (-1 when tMin does).
// False when the ray misses the box.
bool gridSpan(const CellBoundaries& cells, const Ray& ray, const RayAxes& ax, double& tLo, double& tHi,
              int& entryAxis) {
  // Slab test against the closed grid box [b(0), b(n)].
  tLo = ray.tMin;
  tHi = ray.tMax;
  entryAxis = -1;
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    const double gridLo = cells.b[a].front(), gridHi = cells.b[a].back();
    if (d == 0) {
      if (o < gridLo || o > gridHi) return false;
      continue;
    }
    double t0 = ax.crossing(a, gridLo, o, d);
    double t1 = ax.crossing(a, gridHi, o, d);
    if (t0 > t1) std::swap(t0, t1);
    t0 -= ax.tol[a] + kRel * std::fabs(t0);
    t1 += ax.tol[a] + kRel * std::fabs(t1);
    if (t0 > tLo) {
      tLo = t0;
      entryAxis = a;
    }
    tHi = std::min(tHi, t1);
  }
  return tLo <= tHi;
}

}  // namespace

void GridWalker::init(const CellBoundaries& cells, const Ray& ray) {
  done_ = true;
  for (int a = 0; a < 3; ++a) {
    org_[a] = ray.origin[a];
    dir_[a] = ray.direction[a];
    bnd_[a] = cells.b[a].data();
    dims_[a] = cells.dims[a];
  }
  if (!isFinite(ray.origin) || !isFinite(ray.direction) || std::isnan(ray.tMin) || std::isnan(ray.tMax)) return;
  if (ray.direction.x == 0 && ray.direction.y == 0 && ray.direction.z == 0) return;
  if (dims_[0] == 0 || dims_[1] == 0 || dims_[2] == 0) return;

  ax_ = rayAxes(cells, ray);
  double tLo, tExitBox;
  int entry;
  if (!gridSpan(cells, ray, ax_, tLo, tExitBox, entry)) return;
  tHi_ = ray.tMax + hitSlack(ray.tMax);

  // The start cell, from the point at tLo. Each index is biased against the direction of travel by the positional
  // slack, so a start point that rounding put just past a boundary still starts in the cell before it; the walk
  // then steps across at once.
  for (int a = 0; a < 3; ++a) {
    const double p = dir_[a] == 0 ? org_[a] : org_[a] + tLo * dir_[a];
    if (dir_[a] > 0) {
      idx_[a] = cellBelow(cells, a, p - ax_.tolPos[a]);
      step_[a] = 1;
    } else if (dir_[a] < 0) {
      idx_[a] = cellAbove(cells, a, p + ax_.tolPos[a]);
      step_[a] = -1;
    } else {
      idx_[a] = cellBelow(cells, a, p);
      step_[a] = 0;
    }
  }
  for (int a = 0; a < 3; ++a) tNext_[a] = nextT(a);
  tCur_ = tLo;
  entryAxis_ = entry;
  maxSteps_ = dims_[0] + dims_[1] + dims_[2] + 3;
  done_ = false;
}

void GridWalker::queueExtras(int m, double tm, const WalkCell& from, bool n1, bool n2) {
  int others[2], count = 0;
  if (n1) others[count++] = m == 0 ? 1 : 0;
  if (n2) others[count++] = m == 2 ? 1 : 2;
  for (int subset = 1; subset < (1 << count); ++subset) {
    int64_t c[3] = {idx_[0], idx_[1], idx_[2]};
    int lastAxis = -1;
    for (int s = 0; s < count; ++s)
      if (subset & (1 << s)) {
        c[others[s]] += step_[others[s]];
        lastAxis = others[s];
      }
    if (uint64_t(c[0]) < dims_[0] && uint64_t(c[1]) < dims_[1] && uint64_t(c[2]) < dims_[2]) {
      WalkCell& e = queue_[queued_++];
      e = from;
      e.idx = {uint32_t(c[0]), uint32_t(c[1]), uint32_t(c[2])};
      e.tEnter = tm;
      e.entryAxis = lastAxis;
      e.extra = true;
    }
  }
}

// Skips the empty block holding the current cell (no primitive can be found in it). Its exit parameter tX is the
// smallest crossing of its far faces (on axis m). When the ray passes within twice the tolerance of another far face
// at tX (near an edge or corner of the block; by monotony that is where it comes closest), nothing is skipped and the
// ordinary steps with their extra cells handle it. Otherwise every axis is advanced, without reporting cells, over
// the boundaries inside the block that the ray crosses before T = tX - 2 (tol + kRel |tX|): those steps only leave
// cells of the block, and none of their extra cells can lie outside it (the ray is farther than the tolerance from
// the other far faces, and the steps near the exit face come after T). The walker is then in the state the ordinary
// walk reaches at T and goes on from there; every index increment counts as a step, so the bound on steps holds.
//
// `shift` is the block's, or larger when the aligned box of 2^shift cells holding the block is empty as a whole
// (Accel::emptyShift): the argument only needs an aligned box of cells without any primitive, and such a box's faces
// are block faces, so the steps after the jump still look at each new block as they enter it.
void GridWalker::fastForward(uint32_t shift) {
  const int64_t mask = (int64_t(1) << shift) - 1;
  int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = idx_[a] & ~mask;
    hi[a] = std::min<int64_t>(idx_[a] | mask, int64_t(dims_[a]) - 1);
  }
  fastForwardBox(lo, hi);
}

void GridWalker::fastForwardBox(const int64_t lo[3], const int64_t hi[3]) {
  double tB[3];
  int64_t far[3];
  for (int a = 0; a < 3; ++a) {
    if (step_[a] == 0) {
      tB[a] = std::numeric_limits<double>::infinity();
      far[a] = -1;
      continue;
    }
    far[a] = step_[a] > 0 ? hi[a] + 1 : lo[a];
    const double b = bnd_[a][far[a]];
    tB[a] = ax_.crossing(a, b, org_[a], dir_[a]);
  }
  int m = 0;
  if (tB[1] < tB[m]) m = 1;
  if (tB[2] < tB[m]) m = 2;
  const double tX = tB[m];
  if (!std::isfinite(tX)) return;
  for (int a = 0; a < 3; ++a)
    if (a != m && std::isfinite(tB[a]) &&
        (tB[a] - tX) * std::fabs(dir_[a]) <= 2 * (ax_.tolPos[a] + kRel * std::fabs(tX * dir_[a])))
      return;
  const double T = tX - 2 * (ax_.tol[m] + kRel * std::fabs(tX));
  for (int a = 0; a < 3; ++a) {
    if (step_[a] == 0) continue;
    if (std::abs(far[a] - idx_[a]) > kMaxLoopCells) {
      advanceBySearch(a, far[a], T);
      continue;
    }
    while (idx_[a] + (step_[a] > 0 ? 1 : 0) != far[a] && tNext_[a] < T) {
      idx_[a] += step_[a];
      ++steps_;
      if (tNext_[a] > tCur_) {
        tCur_ = tNext_[a];
        entryAxis_ = a;
      }
      tNext_[a] = nextT(a);
    }
  }
}

// fastForward's loop on axis a (step the index while its next boundary is not the box's far one and is crossed
// before T) in O(log n) for a big box: the crossings met along an axis never decrease (the boundaries are sorted and
// (b - o) * inv rounds monotonically), so the loop stops at the first k whose crossing is not below T, found by
// bisection. The state after it is the loop's bit for bit: k more steps, tCur raised to the last crossing passed
// (and the entry axis set) when that exceeds it, and the next crossing. The loop cost one turn per cell of a big box
// (an 8192^3 grid's empty space, a long thin grid's empty run).
void GridWalker::advanceBySearch(int a, int64_t far, double T) {
  const int64_t i0 = idx_[a], s = step_[a];
  // The boundary crossed by the k-th step from i0 (k = 0: the next one) and the number of steps to the box's end.
  const auto boundary = [&](int64_t k) { return s > 0 ? i0 + k + 1 : i0 - k; };
  const int64_t kMax = s > 0 ? far - i0 - 1 : i0 - far;
  const auto crossing = [&](int64_t k) { return ax_.crossing(a, bnd_[a][boundary(k)], org_[a], dir_[a]); };
  int64_t lo = 0, hi = kMax;  // the answer is in [lo, hi]: the first k < kMax with !(crossing(k) < T), else kMax
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (!(crossing(mid) < T))
      hi = mid;
    else
      lo = mid + 1;
  }
  if (lo == 0) return;
  const double last = crossing(lo - 1);
  idx_[a] = i0 + s * lo;
  steps_ += uint64_t(lo);
  if (last > tCur_) {
    tCur_ = last;
    entryAxis_ = a;
  }
  tNext_[a] = nextT(a);
}

namespace {

inline void consider(const Accel& accel, uint32_t id, const Ray& ray, Hit& best, TraceStats& st) {
  double t;
  ++st.tests;
  if (intersectPrimitive(accel, id, ray, t) && closer(t, id, best)) {
    best.t = t;
    best.prim = id;
  }
}

// Tests the primitives at grid->primIds[begin, end) in double, as the walk always did (through the mailbox); keeps
// the nearest hit in `best`. An occlusion query (AnyHit) returns at its first hit; the return value says whether it
// hit.
template <bool AnyHit>
inline bool testRefs(const Accel& accel, uint64_t begin, uint64_t end, const Ray& ray, Mailbox<64>& mailbox, Hit& best,
                     TraceStats& st) {
  for (uint64_t r = begin; r < end; ++r) {
    const uint32_t id = accel.grid->primIds[r];
    if (mailbox.seen(id)) {
      ++st.mailboxSkips;
      continue;
    }
    ++st.tests;
    double t;
    if (intersectCellPrimitive(accel, r, id, ray, t) && closer(t, id, best)) {
      best.t = t;
      best.prim = id;
      if (AnyHit) return true;
    }
  }
  return false;
}

// The primitives of occupied cell c: its triangles through the float filter (float_filter.h), the few it cannot
// reject, and any spheres after them, in double. The double test of a rejected triangle would have missed, so the
// result is the one of testRefs over the whole cell.
template <bool AnyHit>
inline bool testGroups(const Accel& accel, FloatCells::Cell cell, const Ray& ray, const filter::FilterRay& fr,
                       Mailbox<64>& mailbox, Hit& best, TraceStats& st) {
  const TriangleGroup4* g = accel.floatCells.groups.data() + cell.first;
  for (uint32_t k = 0; k < cell.count; k += 4, ++g) {
    const uint32_t lanes = std::min<uint32_t>(cell.count - k, 4);
    uint32_t maybe = filter::maybeHits(*g, fr, lanes);
    // Bits set in a 4-bit value from a table of nibbles: __builtin_popcount is a library call without -mpopcnt.
    st.filtered += lanes - uint32_t((0x4332322132212110ull >> (4 * maybe)) & 0xf);
    for (; maybe != 0; maybe &= maybe - 1) {
      const uint32_t id = g->id[__builtin_ctz(maybe)];
      if (mailbox.seen(id)) {
        ++st.mailboxSkips;
        continue;
      }
      ++st.tests;
      double t;
      if (intersectTriangle(accel.triangles[id], ray, t) && closer(t, id, best)) {
        best.t = t;
        best.prim = id;
        if (AnyHit) return true;
      }
    }
  }
  return false;
}

template <bool AnyHit>
inline bool testCell(const Accel& accel, uint32_t c, const Ray& ray, const filter::FilterRay* fr, Mailbox<64>& mailbox,
                     Hit& best, TraceStats& st) {
  const uint64_t begin = accel.grid->cellStart[c];
  if (!fr) return testRefs<AnyHit>(accel, begin, accel.grid->cellStart[c + 1], ray, mailbox, best, st);
  const FloatCells::Cell cell = accel.floatCells.cells[c];
  if (testGroups<AnyHit>(accel, cell, ray, *fr, mailbox, best, st)) return true;
  if (accel.sphereCount == 0) return false;
  return testRefs<AnyHit>(accel, begin + cell.count, accel.grid->cellStart[c + 1], ray, mailbox, best, st);
}

// The float groups of a walk's cell straight from the block tables (Accel::floatCell), when the scene has only
// triangles in its cells (else testCell, through the occupied-cell index).
inline bool directGroups(const Accel& accel, const filter::FilterRay* fr) {
  return fr && accel.sphereCount == 0 && !accel.floatCells.slots.empty();
}

// The walk over the grid's cells after the always-tested primitives: the nearest hit of the cells' primitives in
// `best` (traceRay), or whether any is hit (occluded, AnyHit).
template <bool AnyHit>
inline bool walkCells(const Accel& accel, const Ray& ray, Hit& best, TraceStats& st) {
  filter::FilterRay filterRay;
  const filter::FilterRay* fr = filter::prepareFilterRay(accel.floatCells, ray, filterRay) ? &filterRay : nullptr;
  const bool direct = directGroups(accel, fr);
  GridWalker walker(accel, ray, EmptySkip::Boxes);
  Mailbox<64> mailbox;
  bool anyHit = false;
  const bool boxes = !accel.cellBoxes.empty();
  // Which side of a cell box lies ahead on each axis (a box reaching only backwards or sideways saves no step).
  const bool ahead[3] = {ray.direction.x > 0, ray.direction.y > 0, ray.direction.z > 0};
  const bool behind[3] = {ray.direction.x < 0, ray.direction.y < 0, ray.direction.z < 0};
  walker.walk([&](const WalkCell& cell) {
    ++st.cells;
    bool hit = false;
    const uint32_t i = cell.idx[0], j = cell.idx[1], k = cell.idx[2];
    if (accel.blockShift == 0) {
      const uint32_t c = accel.lookupSlow(i, j, k);
      if (c < kSolidCell) hit = testCell<AnyHit>(accel, c, ray, fr, mailbox, best, st);
    } else if (const uint64_t slot = accel.slotOf(i, j, k); slot != UINT64_MAX) {
      const uint32_t c = accel.cellSlots[slot];
      if (c < kSolidCell) {
        hit = direct ? testGroups<AnyHit>(accel, accel.floatCells.slots[slot], ray, *fr, mailbox, best, st)
                     : testCell<AnyHit>(accel, c, ray, fr, mailbox, best, st);
      } else if (boxes && !cell.extra) {
        const CellBox& b = accel.cellBoxes[slot];
        if ((ahead[0] & (b.hi[0] != 0)) | (ahead[1] & (b.hi[1] != 0)) | (ahead[2] & (b.hi[2] != 0)) |
            (behind[0] & (b.lo[0] != 0)) | (behind[1] & (b.lo[1] != 0)) | (behind[2] & (b.lo[2] != 0)))
          walker.jumpOver({i - b.lo[0], j - b.lo[1], k - b.lo[2]}, {i + b.hi[0], j + b.hi[1], k + b.hi[2]});
      }
    }
    if (AnyHit) {
      anyHit = hit;
      return hit;
    }
    // A hit may lie beyond this cell (a primitive spanning cells): it is kept, and accepted only once the walk
    // has passed every cell that could hold a nearer one.
    return best.valid() && best.t + walker.hitSlack(best.t) < cell.tExit - cell.exitSlack;
  });
  return anyHit;
}

// The walks compiled three times, for x86-64-v4 (AVX-512: 32 vector registers, so the walk's state and the float
// filter's rows spill less), AVX2 (VEX-encoded float filter and setup, SSE4.1) and the baseline, and picked at load
// time like the packet kernel; `flatten` puts the walker, the filter and the setup into each copy. The arithmetic is
// IEEE in every copy: -ffp-contract=off forbids contracting a * b + c into a fused multiply-add even where the target
// has one (x86-64-v4; tests/cli/no_fused_multiply_add.sh checks the library holds none), so all copies visit the same
// cells and get the same t. intersect.cpp's tests are called out of line, the same code for all. clang refuses
// `flatten` on a multiversioned function (its fuzz build gets two clones with their usual inlining).
#if defined(__clang__)
#define VOX_WALK_COPIES [[gnu::target_clones("avx2", "default")]]
#else
#define VOX_WALK_COPIES [[gnu::target_clones("arch=x86-64-v4", "avx2", "default"), gnu::flatten]]
#endif
VOX_WALK_COPIES void walkNearest(const Accel& accel, const Ray& ray, Hit& best, TraceStats& st) {
  walkCells<false>(accel, ray, best, st);
}
VOX_WALK_COPIES bool walkAny(const Accel& accel, const Ray& ray, TraceStats& st) {
  Hit any;
  return walkCells<true>(accel, ray, any, st);
}
#undef VOX_WALK_COPIES

}  // namespace

Hit traceRay(const Accel& accel, const Ray& ray, TraceStats* stats) {
  TraceStats st;
  st.rays = 1;
  Hit best;
  if (accel.kind == AccelKind::None) {
    const uint32_t n = accel.primitiveCount();
    for (uint32_t id = 0; id < n; ++id) consider(accel, id, ray, best, st);
  } else {
    for (uint32_t id : accel.alwaysTested) consider(accel, id, ray, best, st);
    walkNearest(accel, ray, best, st);
  }
  if (stats) *stats += st;
  return best;
}

bool occluded(const Accel& accel, const Ray& ray, TraceStats* stats) {
  TraceStats st;
  st.rays = 1;
  bool hit = false;
  double t;
  if (accel.kind == AccelKind::None) {
    const uint32_t n = accel.primitiveCount();
    for (uint32_t id = 0; id < n && !hit; ++id) {
      ++st.tests;
      hit = intersectPrimitive(accel, id, ray, t);
    }
  } else {
    for (size_t i = 0; i < accel.alwaysTested.size() && !hit; ++i) {
      ++st.tests;
      hit = intersectPrimitive(accel, accel.alwaysTested[i], ray, t);
    }
    if (!hit) hit = walkAny(accel, ray, st);
  }
  if (stats) *stats += st;
  return hit;
}

CellHit firstOccupiedCell(const Accel& accel, const Ray& ray, TraceStats* stats) {
  TraceStats st;
  st.rays = 1;
  CellHit result;
  GridWalker walker(accel, ray);
  WalkCell cell;
  while (walker.next(cell)) {
    ++st.cells;
    const uint32_t c = accel.lookup(cell.idx[0], cell.idx[1], cell.idx[2]);
    if (c == kEmptyCell) continue;
    result.hit = true;
    result.t = std::max(cell.tEnter, ray.tMin);
    result.idx = cell.idx;
    result.entryAxis = cell.tEnter <= ray.tMin ? -1 : cell.entryAxis;
    result.solid = c == kSolidCell;
    result.primCount = result.solid ? 0 : uint32_t(accel.cellPrims(c).size());
    break;
  }
  if (stats) *stats += st;
  return result;
}

}  // namespace vox
