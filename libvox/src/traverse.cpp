#include "vox/traverse.h"

#include <algorithm>
#include <cstring>

namespace vox {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Fraction of a cell by which boundaries are treated as fuzzy: rays passing this close to an edge or corner also
// visit the cells across it. Costs an extra cell visit about once per million crossings.
constexpr double kCellSlack = 1e-6;

// Largest i in [0, n-1] with b(i) <= c (c below the grid gives 0, above gives n-1).
int64_t cellBelow(const Box& bounds, const std::array<uint32_t, 3>& dims, int a, double c) {
  const int64_t n = dims[a];
  const double lo = bounds.lo[a], hi = bounds.hi[a];
  double guess = std::floor((c - lo) / (hi - lo) * double(n));
  if (!(guess >= 0)) guess = 0;
  if (guess > double(n - 1)) guess = double(n - 1);
  int64_t i = int64_t(guess);
  while (i > 0 && cellBoundary(bounds, dims, a, i) > c) --i;
  while (i < n - 1 && cellBoundary(bounds, dims, a, i + 1) <= c) ++i;
  return i;
}

// Smallest i in [0, n-1] with b(i+1) >= c.
int64_t cellAbove(const Box& bounds, const std::array<uint32_t, 3>& dims, int a, double c) {
  const int64_t n = dims[a];
  int64_t i = cellBelow(bounds, dims, a, c);
  while (i > 0 && cellBoundary(bounds, dims, a, i) >= c) --i;
  while (i < n - 1 && cellBoundary(bounds, dims, a, i + 1) < c) ++i;
  return i;
}

}  // namespace

GridWalker::GridWalker(const Box& bounds, const std::array<uint32_t, 3>& dims, const Ray& ray)
    : bounds_(bounds), dims_(dims) {
  done_ = true;
  for (int a = 0; a < 3; ++a) {
    org_[a] = ray.origin[a];
    dir_[a] = ray.direction[a];
  }
  if (!isFinite(ray.origin) || !isFinite(ray.direction) || std::isnan(ray.tMin) || std::isnan(ray.tMax)) return;
  if (ray.direction.x == 0 && ray.direction.y == 0 && ray.direction.z == 0) return;
  if (dims[0] == 0 || dims[1] == 0 || dims[2] == 0) return;

  double scale = 0, minCell = std::numeric_limits<double>::infinity();
  double gridLo[3], gridHi[3];
  for (int a = 0; a < 3; ++a) {
    gridLo[a] = boundary(a, 0);
    gridHi[a] = boundary(a, dims[a]);
    const double cell = (gridHi[a] - gridLo[a]) / dims[a];
    if (cell > 0) minCell = std::min(minCell, cell);
    const double mag = std::fabs(org_[a]) + std::max(std::fabs(gridLo[a]), std::fabs(gridHi[a]));
    scale = std::max(scale, mag);
    // Positional slack per axis: a fraction of the cell plus the rounding of coordinates of this magnitude.
    tolPos_[a] = kCellSlack * cell + 64 * kEps * mag;
    tol_[a] = dir_[a] != 0 ? tolPos_[a] / std::fabs(dir_[a]) : 0;
  }
  if (!std::isfinite(minCell)) minCell = 0;
  const double dirLength = length(ray.direction);
  hitSlack_ = (kCellSlack * minCell + 64 * kEps * scale) / dirLength;

  // Slab test against the closed grid box [b(0), b(n)].
  double tLo = ray.tMin, tExitBox = ray.tMax;
  int entry = -1;
  for (int a = 0; a < 3; ++a) {
    if (dir_[a] == 0) {
      if (org_[a] < gridLo[a] || org_[a] > gridHi[a]) return;
      continue;
    }
    double t0 = (gridLo[a] - org_[a]) / dir_[a];
    double t1 = (gridHi[a] - org_[a]) / dir_[a];
    if (t0 > t1) std::swap(t0, t1);
    t0 -= tol_[a] + kRel * std::fabs(t0);
    t1 += tol_[a] + kRel * std::fabs(t1);
    if (t0 > tLo) {
      tLo = t0;
      entry = a;
    }
    tExitBox = std::min(tExitBox, t1);
  }
  if (!(tLo <= tExitBox)) return;
  tHi_ = ray.tMax + hitSlack(ray.tMax);

  // The start cell, from the point at tLo. Each index is biased against the direction of travel by the positional
  // slack, so a start point that rounding put just past a boundary still starts in the cell before it; the walk
  // then steps across at once.
  for (int a = 0; a < 3; ++a) {
    const double p = dir_[a] == 0 ? org_[a] : org_[a] + tLo * dir_[a];
    if (dir_[a] > 0) {
      idx_[a] = cellBelow(bounds, dims, a, p - tolPos_[a]);
      step_[a] = 1;
    } else if (dir_[a] < 0) {
      idx_[a] = cellAbove(bounds, dims, a, p + tolPos_[a]);
      step_[a] = -1;
    } else {
      idx_[a] = cellBelow(bounds, dims, a, p);
      step_[a] = 0;
    }
  }
  for (int a = 0; a < 3; ++a) tNext_[a] = nextT(a);
  tCur_ = tLo;
  entryAxis_ = entry;
  maxSteps_ = uint64_t(dims[0]) + dims[1] + dims[2] + 3;
  done_ = false;
}

namespace {

// Per-ray mailbox (Amanatides & Woo 1987; Kirk & Arvo): a direct-mapped cache of the ids tested by this ray. It
// lives on the stack of the tracing thread, so it needs no synchronisation. A collision only causes a repeated
// test, which returns the same t, so correctness never depends on it.
struct Mailbox {
  static constexpr uint32_t kSize = 64;
  uint32_t ids[kSize];
  Mailbox() { std::memset(ids, 0xff, sizeof(ids)); }
  // True when `id` was already tested; records it otherwise.
  bool seen(uint32_t id) {
    uint32_t& slot = ids[id & (kSize - 1)];
    if (slot == id) return true;
    slot = id;
    return false;
  }
};

inline bool testPrim(const Accel& accel, uint32_t id, const Ray& ray, double& t) {
  if (id < accel.triangleCount) return intersectTriangle(accel.triangles[id], ray, t);
  const uint32_t s = id - accel.triangleCount;
  if (s < accel.sphereCount) return intersectSphere(accel.spheres[s], ray, t);
  return intersectPlane(accel.planes[s - accel.sphereCount], ray, t);
}

inline void consider(const Accel& accel, uint32_t id, const Ray& ray, Hit& best, TraceStats& st) {
  double t;
  ++st.tests;
  if (testPrim(accel, id, ray, t) && closer(t, id, best)) {
    best.t = t;
    best.prim = id;
  }
}

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
    const Grid& grid = *accel.grid;
    GridWalker walker(grid.bounds, grid.dims, ray);
    Mailbox mailbox;
    WalkCell cell;
    while (walker.next(cell)) {
      ++st.cells;
      const uint32_t c = accel.lookup(cell.idx[0], cell.idx[1], cell.idx[2]);
      if (c < kSolidCell) {
        for (uint32_t id : accel.cellPrims(c)) {
          if (mailbox.seen(id)) {
            ++st.mailboxSkips;
            continue;
          }
          consider(accel, id, ray, best, st);
        }
      }
      // A hit may lie beyond this cell (a primitive spanning cells): it is kept, and accepted only once the walk
      // has passed every cell that could hold a nearer one.
      if (best.valid() && best.t + walker.hitSlack(best.t) < cell.tExit - cell.exitSlack) break;
    }
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
      hit = testPrim(accel, id, ray, t);
    }
  } else {
    for (size_t i = 0; i < accel.alwaysTested.size() && !hit; ++i) {
      ++st.tests;
      hit = testPrim(accel, accel.alwaysTested[i], ray, t);
    }
    const Grid& grid = *accel.grid;
    GridWalker walker(grid.bounds, grid.dims, ray);
    Mailbox mailbox;
    WalkCell cell;
    while (!hit && walker.next(cell)) {
      ++st.cells;
      const uint32_t c = accel.lookup(cell.idx[0], cell.idx[1], cell.idx[2]);
      if (c >= kSolidCell) continue;
      for (uint32_t id : accel.cellPrims(c)) {
        if (mailbox.seen(id)) {
          ++st.mailboxSkips;
          continue;
        }
        ++st.tests;
        if (testPrim(accel, id, ray, t)) {
          hit = true;
          break;
        }
      }
    }
  }
  if (stats) *stats += st;
  return hit;
}

CellHit firstOccupiedCell(const Accel& accel, const Ray& ray, TraceStats* stats) {
  TraceStats st;
  st.rays = 1;
  CellHit result;
  const Grid& grid = *accel.grid;
  GridWalker walker(grid.bounds, grid.dims, ray);
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
