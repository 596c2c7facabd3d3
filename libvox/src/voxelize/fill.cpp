#include "vox/voxelize/fill.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <memory>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/core/resize_in_steps.h"
#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/overlap.h"
#include "vox/voxelize/winding_number.h"

namespace vox {

namespace {

// The grid seen as rows along x. Only rows holding an occupied cell are listed: a row without one is a single empty
// run from face to face of the grid, outside by definition. A gap is an empty run between two occupied cells of
// one row; every other empty run of a listed row touches an x face of the grid and is outside too. So everything
// the fill must decide lives in the gaps, and there are fewer gaps than occupied cells.
struct RowTable {
  std::vector<uint64_t> row;        // row ids j + ny * k, ascending
  std::vector<uint64_t> cellBegin;  // occupied cells of row r: grid.cellKeys[cellBegin[r] .. cellBegin[r + 1])
  std::vector<uint64_t> gapBegin;   // gaps of row r: gaps[gapBegin[r] .. gapBegin[r + 1])
  std::vector<CellRun> gaps;        // in key order
};

// Union-find over the gaps (node g + 1) and the outside (node 0, always a root: the smaller root wins).
struct UnionFind {
  std::vector<uint64_t> parent;
  uint64_t find(uint64_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  uint64_t findConst(uint64_t x) const {  // safe to call from several threads
    while (parent[x] != x) x = parent[x];
    return x;
  }
  void unite(uint64_t a, uint64_t b) {
    a = find(a), b = find(b);
    if (a < b)
      parent[b] = a;
    else if (b < a)
      parent[a] = b;
  }
};

struct Interval {
  uint32_t lo, hi;  // x range, inclusive
  uint64_t node;    // linkGaps' union-find node: gap + 1, or 0 for a run that touches an x face (outside)
  uint64_t slot;    // the run's slot (firstSlot)
};

// Asks FillOptions::progress whether to go on, from a serial phase on the calling thread (every 4096th step of its
// loop), at the fraction the fill has reached; throws when told to stop. The serial phases (the row table, the flood
// links, the run groups) take tenths of a second each on a 1024^3 grid: longer than Ctrl-C may wait.
struct CancelCheck {
  const FillOptions* options = nullptr;
  double fraction = 0;
  void operator()(uint64_t step = 0) const {
    if (options && options->progress && (step & 4095) == 0 && !options->progress(fraction))
      fail<Error>("solid fill cancelled");
  }
};

// n copies of `value`, filled 8 MiB at a time with `check` asked between: filling fresh pages runs on the calling
// thread alone, 0.1 to 0.2 s for each slot array of a 2048^3 grid.
template <typename T>
std::vector<T> slotVector(size_t n, const T& value, const CancelCheck& check) {
  std::vector<T> v;
  resizeInSteps(v, n, value, [&] { check(); });
  return v;
}

// Scratch bytes per listed row and per gap (row table, union-find, flags, solid pieces, the output runs at worst).
constexpr double kBytesPerRow = 24 + 16 + 16, kBytesPerGap = 16 + 8 + 1 + 8 + 16;

RowTable buildRows(const Grid& grid, uint64_t memoryLimitBytes, const CancelCheck& check = {}) {
  const uint64_t nx = grid.dims[0];
  const auto& keys = grid.cellKeys;
  uint64_t rows = 0, gaps = 0;  // counted first so that the budget is checked before allocating
  for (size_t c = 0; c < keys.size(); ++c) {
    check(c);
    if (c == 0 || keys[c] / nx != keys[c - 1] / nx)
      ++rows;
    else if (keys[c] > keys[c - 1] + 1)
      ++gaps;
  }
  const double needed = kBytesPerRow * double(rows) + kBytesPerGap * double(gaps);
  if (needed > double(memoryLimitBytes))
    fail<LimitError>("solid fill of a ", grid.dims[0], "x", grid.dims[1], "x", grid.dims[2], " grid needs about ",
                     uint64_t(needed / (1 << 20)), " MiB of scratch memory, more than the ", memoryLimitBytes >> 20,
                     " MiB allowed");
  RowTable t;
  t.row.reserve(rows);
  t.cellBegin.reserve(rows + 1);
  t.gapBegin.reserve(rows + 1);
  t.gaps.reserve(gaps);
  for (size_t c = 0; c < keys.size(); ++c) {
    check(c);
    if (c == 0 || keys[c] / nx != keys[c - 1] / nx) {
      t.row.push_back(keys[c] / nx);
      t.cellBegin.push_back(c);
      t.gapBegin.push_back(t.gaps.size());
    } else if (keys[c] > keys[c - 1] + 1) {
      t.gaps.push_back({keys[c - 1] + 1, keys[c] - keys[c - 1] - 1});
    }
  }
  t.cellBegin.push_back(keys.size());
  t.gapBegin.push_back(t.gaps.size());
  return t;
}

// Each listed row r owns the slots [gapBegin[r] + 2r, gapBegin[r + 1] + 2(r + 1)): one before its first occupied
// cell, one per gap, one after its last occupied cell, so that rows fill their slots in parallel.
uint64_t firstSlot(const RowTable& t, size_t r) { return t.gapBegin[r] + 2 * r; }

// The empty runs of listed row r in x order: the one before its first occupied cell, its gaps, the one after.
void rowIntervals(const RowTable& t, const Grid& grid, size_t r, std::vector<Interval>& out) {
  out.clear();
  const uint64_t nx = grid.dims[0], base = t.row[r] * nx, slot = firstSlot(t, r);
  const uint64_t firstX = grid.cellKeys[t.cellBegin[r]] - base, lastX = grid.cellKeys[t.cellBegin[r + 1] - 1] - base;
  if (firstX > 0) out.push_back({0, uint32_t(firstX - 1), 0, slot});
  for (uint64_t g = t.gapBegin[r]; g < t.gapBegin[r + 1]; ++g) {
    const uint64_t lo = t.gaps[g].first - base;
    out.push_back({uint32_t(lo), uint32_t(lo + t.gaps[g].count - 1), g + 1, slot + 1 + (g - t.gapBegin[r])});
  }
  if (lastX + 1 < nx) out.push_back({uint32_t(lastX + 1), uint32_t(nx - 1), 0, firstSlot(t, r + 1) - 1});
}

// Joins the empty runs of two face-adjacent rows that share an x index (the cells there are 6-neighbours):
// unites label(a) and label(b) for each such pair whose labels are both >= 0.
template <typename Label>
void linkRows(const std::vector<Interval>& a, const std::vector<Interval>& b, UnionFind& uf, const Label& label) {
  size_t p = 0, q = 0;
  while (p < a.size() && q < b.size()) {
    if (a[p].hi < b[q].lo)
      ++p;
    else if (b[q].hi < a[p].lo)
      ++q;
    else {
      const int64_t la = label(a[p]), lb = label(b[q]);
      if (la >= 0 && lb >= 0) uf.unite(uint64_t(la), uint64_t(lb));
      if (a[p].hi < b[q].hi)
        ++p;
      else
        ++q;
    }
  }
}

// Face-connected groups of the runs that `keep` accepts, as a union-find over slots. Only listed rows are swept,
// so runs joined through a row without surface cells stay in separate groups (one more evaluation, never wrong).
template <typename Keep>
UnionFind linkRuns(const RowTable& t, const Grid& grid, const Keep& keep, const CancelCheck& check) {
  UnionFind uf;
  uf.parent = slotVector<uint64_t>(t.gapBegin.back() + 2 * t.row.size(), 0, check);
  for (uint64_t n = 0; n < uf.parent.size(); ++n) {
    check(n);
    uf.parent[n] = n;
  }
  const uint64_t ny = grid.dims[1], nz = grid.dims[2];
  auto label = [&](const Interval& run) { return keep(run) ? int64_t(run.slot) : int64_t(-1); };
  size_t cursor[2] = {0, 0};
  std::vector<Interval> mine, theirs;
  for (size_t r = 0; r < t.row.size(); ++r) {
    check(r);
    const uint64_t id = t.row[r], j = id % ny, k = id / ny;
    rowIntervals(t, grid, r, mine);
    for (int o = 0; o < 2; ++o) {
      if (o == 0 ? j + 1 >= ny : k + 1 >= nz) continue;
      const uint64_t target = id + (o == 0 ? 1 : ny);
      while (cursor[o] < t.row.size() && t.row[cursor[o]] < target) ++cursor[o];
      if (cursor[o] == t.row.size() || t.row[cursor[o]] != target) continue;
      rowIntervals(t, grid, cursor[o], theirs);
      linkRows(mine, theirs, uf, label);
    }
  }
  for (uint64_t n = 0; n < uf.parent.size(); ++n) uf.find(n);  // compressed: findConst is then one step
  return uf;
}

// The planes a table covers, and whether its lowest and highest planes continue into other slabs (SlabFill): the
// links across those faces are the other slabs', so they are neither made nor taken as the outside.
struct PlaneRange {
  uint64_t low = 0, high = 0;
  bool continuesBelow = false, continuesAbove = false;
};

// 6-connected components of the empty cells, over runs: a gap is enclosed when its component does not reach
// the outside. Each pair of listed neighbouring rows is swept once, from the lower row; a neighbour that is not
// listed (or lies outside the grid) is all empty and outside.
UnionFind linkGaps(const RowTable& t, const Grid& grid, const PlaneRange& planes = {}, const CancelCheck& check = {}) {
  UnionFind uf;
  uf.parent.resize(t.gaps.size() + 1);
  for (uint64_t n = 0; n < uf.parent.size(); ++n) uf.parent[n] = n;
  const uint64_t ny = grid.dims[1], nz = grid.dims[2];
  const int64_t offsets[4] = {-int64_t(ny), -1, 1, int64_t(ny)};
  size_t cursor[4] = {0, 0, 0, 0};  // per offset, first listed row >= target; targets only grow
  std::vector<Interval> mine, theirs;
  for (size_t r = 0; r < t.row.size(); ++r) {
    check(r);
    const uint64_t id = t.row[r], j = id % ny, k = id / ny;
    const bool hasGaps = t.gapBegin[r + 1] > t.gapBegin[r];
    bool loaded = false;
    for (int o = 0; o < 4; ++o) {
      if ((o == 0 && planes.continuesBelow && k == planes.low) || (o == 3 && planes.continuesAbove && k == planes.high))
        continue;
      const bool inGrid = o == 0 ? k > 0 : o == 1 ? j > 0 : o == 2 ? j + 1 < ny : k + 1 < nz;
      if (!inGrid) {
        for (uint64_t g = t.gapBegin[r]; g < t.gapBegin[r + 1]; ++g) uf.unite(0, g + 1);
        continue;
      }
      const uint64_t target = id + offsets[o];
      while (cursor[o] < t.row.size() && t.row[cursor[o]] < target) ++cursor[o];
      const size_t n = cursor[o];
      if (n == t.row.size() || t.row[n] != target) {
        for (uint64_t g = t.gapBegin[r]; g < t.gapBegin[r + 1]; ++g) uf.unite(0, g + 1);
      } else if (o >= 2 && (hasGaps || t.gapBegin[n + 1] > t.gapBegin[n])) {
        if (!loaded) rowIntervals(t, grid, r, mine), loaded = true;
        rowIntervals(t, grid, n, theirs);
        linkRows(mine, theirs, uf, [](const Interval& run) { return int64_t(run.node); });
      }
    }
  }
  return uf;
}

// Generalized winding number of the whole scene: triangles by the tree, each sphere or ellipsoid exactly (1 inside).
struct SceneWinding {
  WindingTree tree;
  std::vector<Sphere> spheres;  // ellipsoids mapped back to their sphere: transform replaced by its inverse

  explicit SceneWinding(const Scene& scene) : tree(buildWindingTree(scene.triangles)), spheres(scene.spheres) {
    for (Sphere& s : spheres)
      if (s.isEllipsoid()) s.transform = inverse(s.transform);
  }
  double at(const Vec3& q) const {
    // The decision is the exact one except where the exact value itself is within 1e-3 of the threshold.
    return windingNumberToDecide(tree, q, 0, kWindingThreshold) + inSpheres(q);
  }
  // The fast value alone: enough to round w + s to the integer k (HoleCaps).
  double rough(const Vec3& q) const { return windingNumber(tree, q) + inSpheres(q); }
  double inSpheres(const Vec3& q) const {
    double w = 0;
    for (const Sphere& s : spheres) {
      const Vec3 p = s.isEllipsoid() ? transformPoint(s.transform, q) : q;
      const Vec3 d = p - s.center;
      if (dot(d, d) < s.radius * s.radius) w += 1;
    }
    return w;
  }
};

// A solid part [lo, hi] of an empty run, x indices within its row; empty when lo > hi.
struct Piece {
  uint32_t lo = 1, hi = 0;
};

// Decides one empty run from `inside(x)`, a decision that changes along the run continuously (its cells meet no
// surface): both end cells are evaluated; when they disagree the run is split where the decision changes
// (bisection, assuming one crossing).
template <typename Inside>
Piece decideRun(uint32_t lo, uint32_t hi, const Inside& inside) {
  const bool a = inside(lo), b = lo == hi ? a : inside(hi);
  if (a == b) return a ? Piece{lo, hi} : Piece{};
  uint32_t l = lo, h = hi;  // inside(l) == a, inside(h) == b
  while (h - l > 1) {
    const uint32_t m = l + (h - l) / 2;
    (inside(m) == a ? l : h) = m;
  }
  return a ? Piece{lo, l} : Piece{h, hi};
}

// The holes' caps. Cap each boundary of the mesh by the cone from its box centre (OpenBoundary::cap, inside that
// box): the mesh with its caps is closed, so its winding number is an integer k, constant in each region that
// neither the surface nor a cap crosses, and the mesh's own winding number is w = k - s, s the caps' winding number.
// Empty runs whose boxes meet no cap, joined face to face, share k: one evaluation of w + s finds it for a whole
// group. Where capWindingBound stays under kCapBoundForInteger (open_edges.h), k alone decides. Nearer the holes the
// runs are decided by k - s, s from the caps' own small tree; only runs that a cap crosses need w itself.
struct HoleCaps {
  bool enabled = false;
  std::vector<OpenBoundary> boundaries;
  std::vector<Triangle> triangles;  // every boundary's cap
  WindingTree tree;                 // over `triangles`

  HoleCaps(std::vector<OpenBoundary>&& openBoundaries, bool leaky) {
    // Gaps in a `center` surface join cells on both sides of it: no constant k between them.
    if (leaky) return;
    boundaries = std::move(openBoundaries);
    enabled = boundaries.size() <= kMaxCapBoundaries;
    if (!enabled) return;
    for (const OpenBoundary& b : boundaries) triangles.insert(triangles.end(), b.cap.begin(), b.cap.end());
    tree = buildWindingTree(triangles);
  }
  // Bound on |s| over `run`; infinite when the run meets a boundary's box.
  double bound(const Box& run) const { return capWindingBound(boundaries, run); }
  // Whether a cap may meet the closed box `run` (sat never misses a contact).
  bool meets(const Box& run) const {
    for (const OpenBoundary& b : boundaries) {
      if (!overlaps(b.bounds, run)) continue;
      for (const Triangle& t : b.cap) {
        const Box tb{minVec(minVec(t.v[0], t.v[1]), t.v[2]), maxVec(maxVec(t.v[0], t.v[1]), t.v[2])};
        if (overlaps(tb, run) && triangleBoxSat(t, run)) return true;
      }
    }
    return false;
  }
  // Where the line through p along `axis`, between `lo` and `hi` on that axis, crosses the caps: the position and
  // the change of k when crossing towards +axis, sorted. The line's sample points lie at first + i * spacing. False
  // when a crossing is too near a cap triangle's edge (the line may pass between two triangles of a fan) or a sample
  // point (where s jumps) to be placed for sure: the caller then falls back to w itself.
  bool crossings(int axis, const Vec3& p, double lo, double hi, double first, double spacing,
                 std::vector<std::pair<double, int>>& out) const {
    out.clear();
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // the normal's `axis` component is the orientation in (u, v)
    Box line{p, p};
    line.lo.at(axis) = lo, line.hi.at(axis) = hi;
    for (const OpenBoundary& b : boundaries) {
      if (!overlaps(b.bounds, line)) continue;
      for (const Triangle& t : b.cap) {
        // Orientations of p against the triangle's edges in the (u, v) plane, with a rounding bound (Shewchuk's
        // orient2d bound is 3.3e-16 of the products' magnitude; ours is far looser).
        double e[3], err[3];
        for (int i = 0; i < 3; ++i) {
          const Vec3 &m = t.v[i], &n = t.v[(i + 1) % 3];
          const double l = (n[u] - m[u]) * (p[v] - m[v]), r = (n[v] - m[v]) * (p[u] - m[u]);
          e[i] = l - r;
          err[i] = 1e-12 * (std::abs(l) + std::abs(r));
        }
        bool pos = false, neg = false, unsure = false;
        for (int i = 0; i < 3; ++i) {
          if (e[i] > err[i])
            pos = true;
          else if (e[i] < -err[i])
            neg = true;
          else
            unsure = true;
        }
        if (pos && neg) continue;  // the line misses this triangle
        if (unsure) return false;
        // Barycentric weights: v[0] by the edge opposite to it (e[1]), v[1] by e[2], v[2] by e[0].
        const double at = (e[1] * t.v[0][axis] + e[2] * t.v[1][axis] + e[0] * t.v[2][axis]) / (e[0] + e[1] + e[2]);
        if (at < lo || at > hi) continue;
        const double phase = (at - first) / spacing;
        if (std::abs(phase - std::round(phase)) < 1e-6) return false;
        // Crossing towards +axis takes the point from the triangle's back (s near +1/2) to its front (s near -1/2)
        // when the normal points to +axis (pos), and w = k - s is continuous: k drops by one.
        out.push_back({at, pos ? -1 : 1});
      }
    }
    std::sort(out.begin(), out.end());
    return true;
  }
  // The caps' winding number at q, close enough to decide |k - s| >= 0.5 as the exact value does.
  double at(const Vec3& q, int64_t k) const { return windingNumberToDecide(tree, q, double(k), kWindingThreshold); }
  static bool overlaps(const Box& a, const Box& b) {
    for (int i = 0; i < 3; ++i)
      if (a.hi[i] < b.lo[i] || b.hi[i] < a.lo[i]) return false;
    return true;
  }
};

Box runBox(const Grid& grid, uint64_t rowBase, const Interval& run) {
  const auto lo = cellIndex(grid.dims, rowBase + run.lo);
  Box b = cellBox(grid, lo[0], lo[1], lo[2]);
  b.hi.x = cellBoundary(grid.bounds, grid.dims, 0, int64_t(run.hi) + 1);
  return b;
}

// Per slot: what the winding stage must do with it.
enum SlotState : uint8_t { kNone = 0, kByInteger = 1, kByCaps = 2, kCrossed = 3, kDecided = 4 };
constexpr int64_t kUnknown = std::numeric_limits<int64_t>::min();  // a group whose k could not be told
// Whether a slot's run waits for its group's k (it meets no cap).
bool sharesK(uint8_t state) { return state == kByInteger || state == kByCaps; }

// Runs the empty runs of each listed row from `firstRow` on through `body(r, run, counts)` in parallel, with
// progress and cancellation.
struct RowSweep {
  const RowTable& t;
  const Grid& grid;
  const FillOptions& options;
  size_t firstRow = 0;
  std::atomic<uint64_t> done{0}, full{0}, caps{0};
  std::atomic<bool> cancelled{false};

  template <typename Body>
  void operator()(const Body& body) {
    const size_t rows = t.row.size() - firstRow;
    tbb::parallel_for(tbb::blocked_range<size_t>(firstRow, t.row.size(), 64),
                      [&](const tbb::blocked_range<size_t>& range) {
                        if (cancelled) return;
                        std::vector<Interval> runs;
                        uint64_t counts[2] = {0, 0};  // full and cap evaluations
                        for (size_t r = range.begin(); r < range.end(); ++r) {
                          rowIntervals(t, grid, r, runs);
                          for (const Interval& run : runs) body(r, run, counts);
                        }
                        full += counts[0], caps += counts[1];
                        const uint64_t finished = done += range.size();
                        if (options.progress && !options.progress(double(finished) / double(2 * rows)))
                          cancelled = true;
                      });
    if (cancelled) fail<Error>("solid fill cancelled");
  }
};

// k of each group of runs sharing it (HoleCaps), at the group's root slot: w + s at the root run's middle cell,
// rounded; kUnknown when w + s lies too far from an integer to trust (a mesh whose boundary we misjudged).
std::vector<int64_t> groupIntegers(const Grid& grid, const RowTable& t, const SceneWinding& w, const HoleCaps& caps,
                                   const UnionFind& groups, const std::vector<uint8_t>& state, RowSweep& sweep) {
  struct Root {
    uint64_t slot, key;
  };
  std::vector<Root> roots;
  std::vector<Interval> runs;
  const uint64_t nx = grid.dims[0];
  const CancelCheck check{&sweep.options, 0.5};
  for (size_t r = 0; r < t.row.size(); ++r) {
    check(r);
    rowIntervals(t, grid, r, runs);
    for (const Interval& run : runs)
      if (sharesK(state[run.slot]) && groups.findConst(run.slot) == run.slot)
        roots.push_back({run.slot, t.row[r] * nx + run.lo + (run.hi - run.lo) / 2});
  }
  std::vector<int64_t> k = slotVector(state.size(), kUnknown, check);
  tbb::parallel_for(size_t(0), roots.size(), [&](size_t i) {
    const Vec3 q = cellCentre(grid, roots[i].key);
    const double v = w.rough(q) + windingNumberExact(caps.triangles, q);
    if (std::abs(v - std::round(v)) <= 0.25) k[roots[i].slot] = int64_t(std::llround(v));
  });
  sweep.full += roots.size();
  return k;
}

// k at cell x of listed row r (centre `q`) from a face neighbour in the next or previous row along y or z, when
// that cell belongs to a cap-free run whose group's k is known; kUnknown otherwise.
int64_t neighbourK(const Grid& grid, const RowTable& t, const HoleCaps& caps, const std::vector<uint8_t>& state,
                   const std::vector<int64_t>& groupK, const UnionFind& groups, size_t r, uint32_t x, const Vec3& q) {
  thread_local std::vector<Interval> near;
  thread_local std::vector<std::pair<double, int>> cuts;
  const uint64_t nx = grid.dims[0], ny = grid.dims[1], id = t.row[r], j = id % ny, kz = id / ny;
  for (int o = 0; o < 4; ++o) {
    const int axis = o < 2 ? 1 : 2;
    const bool up = o % 2;
    if (up ? (axis == 1 ? j + 1 >= ny : kz + 1 >= grid.dims[2]) : (axis == 1 ? j == 0 : kz == 0)) continue;
    const uint64_t step = axis == 1 ? 1 : ny, target = up ? id + step : id - step;
    const auto it = std::lower_bound(t.row.begin(), t.row.end(), target);
    if (it == t.row.end() || *it != target) continue;
    rowIntervals(t, grid, size_t(it - t.row.begin()), near);
    for (const Interval& other : near) {
      if (other.lo > x || other.hi < x || !sharesK(state[other.slot])) continue;
      const int64_t known = groupK[groups.findConst(other.slot)];
      const Vec3 from = cellCentre(grid, target * nx + x);
      const double lo = std::min(from[axis], q[axis]), hi = std::max(from[axis], q[axis]);
      if (known == kUnknown || !caps.crossings(axis, q, lo, hi, lo, hi - lo, cuts)) break;
      int64_t k = known;
      for (const auto& cut : cuts) k += up ? -cut.second : cut.second;  // walking from `from` to q
      return k;
    }
  }
  return kUnknown;
}

}  // namespace

// What the WindingNumber rule evaluates, built from the scene alone: once per fill (SlabFill: not once per slab; the
// tree of the 69k bunny takes about 90 ms).
struct FillWinding {
  SceneWinding scene;
  HoleCaps caps;
  double yzLo[2] = {INFINITY, INFINITY}, yzHi[2] = {-INFINITY, -INFINITY};  // the (y, z) box of every primitive
  FillWinding(const Scene& s, std::vector<OpenBoundary>&& boundaries, const Grid& grid)
      : scene(s), caps(std::move(boundaries), grid.method == OverlapMethod::Center) {
    const size_t nTri = s.triangles.size();
    for (size_t id = 0; id < s.boundedCount(); ++id) {
      const Box b = id < nTri ? triangleBounds(s.triangles[id]) : sphereBounds(s.spheres[id - nTri]);
      for (int a = 0; a < 2; ++a) yzLo[a] = std::min(yzLo[a], b.lo[a + 1]), yzHi[a] = std::max(yzHi[a], b.hi[a + 1]);
    }
  }
};

namespace {

// The solid part of every empty run of the listed rows: enclosed gaps whole; under the WindingNumber rule the other
// runs by their group's k (HoleCaps), by k minus the caps' winding number, or, where a cap crosses the run, by the
// winding number itself (`winding` given: the WindingNumber rule). Rows before `firstRow` (a SlabFill's plane below the
// slab) are left undecided and serve no neighbour. Returns the evaluations of the mesh's winding number and of the
// caps'.
std::pair<uint64_t, uint64_t> decideRuns(const Grid& grid, const FillWinding* winding, const RowTable& t,
                                         const std::vector<uint8_t>& enclosed, const FillOptions& options,
                                         size_t firstRow, std::vector<Piece>& pieces) {
  const SceneWinding* w = winding ? &winding->scene : nullptr;
  const HoleCaps* caps = winding ? &winding->caps : nullptr;
  std::vector<uint8_t> state = slotVector<uint8_t>(pieces.size(), kNone, CancelCheck{&options, 0});
  RowSweep sweep{t, grid, options, firstRow};
  const uint64_t nx = grid.dims[0];
  auto byWinding = [&](size_t r, const Interval& run, uint64_t* counts) {
    return decideRun(run.lo, run.hi, [&](uint32_t x) {
      ++counts[0];
      return std::abs(w->at(cellCentre(grid, t.row[r] * nx + x))) >= kWindingThreshold;
    });
  };
  // A run that a cap crosses: k at its first cell, then changed at each crossing; the cells decided by k - s.
  // k at the first cell comes from a neighbouring row's cap-free run, across the crossings between the two cell
  // centres, or else from one evaluation of w + s there.
  auto crossedRun = [&](size_t r, const Interval& run, const Box& box, const std::vector<int64_t>& groupK,
                        const UnionFind& groups, uint64_t* counts) {
    thread_local std::vector<std::pair<double, int>> cuts;
    const uint64_t rowBase = t.row[r] * nx;
    const Vec3 first = cellCentre(grid, rowBase + run.lo);
    const double width = cellBoundary(grid.bounds, grid.dims, 0, int64_t(run.lo) + 1) - box.lo.x;
    if (!caps->crossings(0, first, box.lo.x, box.hi.x, first.x, width, cuts)) return byWinding(r, run, counts);
    int64_t k0 = neighbourK(grid, t, *caps, state, groupK, groups, r, run.lo, first);
    if (k0 == kUnknown) {
      ++counts[0];
      const double v = w->rough(first) + windingNumber(caps->tree, first);
      if (std::abs(v - std::round(v)) > 0.25) return byWinding(r, run, counts);
      k0 = std::llround(v);
    }
    return decideRun(run.lo, run.hi, [&](uint32_t x) {
      ++counts[1];
      const Vec3 q = cellCentre(grid, rowBase + x);
      int64_t k = k0;
      for (const auto& [at, dk] : cuts)
        if (first.x < at && at < q.x) k += dk;
      return std::abs(double(k) - caps->at(q, k)) >= kWindingThreshold;
    });
  };
  // Pass 1: enclosed gaps, and every run when there are no caps; the others wait for their group's k.
  sweep([&](size_t r, const Interval& run, uint64_t* counts) {
    if (run.node && enclosed[run.node - 1] && !options.windingOnly) {
      pieces[run.slot] = {run.lo, run.hi};
      state[run.slot] = kDecided;
    } else if (winding) {
      const Box box = runBox(grid, t.row[r] * nx, run);
      if (!caps->enabled) {
        pieces[run.slot] = byWinding(r, run, counts);
        state[run.slot] = kDecided;
      } else {
        state[run.slot] = caps->bound(box) <= kCapBoundForInteger ? kByInteger : caps->meets(box) ? kCrossed : kByCaps;
      }
    }
  });
  if (!winding || !caps->enabled) return {sweep.full, sweep.caps};
  const UnionFind groups = linkRuns(
      t, grid, [&](const Interval& run) { return sharesK(state[run.slot]); }, CancelCheck{&options, 0.5});
  const std::vector<int64_t> k = groupIntegers(grid, t, *w, *caps, groups, state, sweep);
  // Pass 2: the waiting runs, by k alone, by k - s, or by w itself when k could not be told.
  sweep([&](size_t r, const Interval& run, uint64_t* counts) {
    if (state[run.slot] == kCrossed) {
      pieces[run.slot] = crossedRun(r, run, runBox(grid, t.row[r] * nx, run), k, groups, counts);
      return;
    }
    if (!sharesK(state[run.slot])) return;
    const int64_t kRun = k[groups.findConst(run.slot)];
    if (kRun == kUnknown) {
      pieces[run.slot] = byWinding(r, run, counts);
    } else if (state[run.slot] == kByInteger) {
      if (kRun != 0) pieces[run.slot] = {run.lo, run.hi};
    } else {
      pieces[run.slot] = decideRun(run.lo, run.hi, [&](uint32_t x) {
        ++counts[1];
        return std::abs(double(kRun) - caps->at(cellCentre(grid, t.row[r] * nx + x), kRun)) >= kWindingThreshold;
      });
    }
  });
  return {sweep.full, sweep.caps};
}
// The report's rule, and under the WindingNumber rule what it evaluates (`winding`), from the scene alone; LimitError
// when the winding tree would not fit.
FillReport startFill(const Grid& grid, const Scene& scene, const FillOptions& options,
                     std::shared_ptr<const FillWinding>& winding) {
  FillReport report;
  report.leakyMethod = grid.method == OverlapMethod::Center;
  // The tree and its build, the edge weld, and the holes' caps (up to three triangles per triangle).
  const double treeBytes = 640.0 * double(scene.triangles.size());
  if (treeBytes > double(options.memoryLimitBytes))
    fail<LimitError>("solid fill of ", scene.triangles.size(), " triangles needs about ",
                     uint64_t(treeBytes / (1 << 20)), " MiB of scratch memory, more than the ",
                     options.memoryLimitBytes >> 20, " MiB allowed");
  std::vector<OpenBoundary> boundaries = openBoundaries(scene.triangles, &report.openEdges, kMaxCapBoundaries);
  CancelCheck{&options, 0}();  // the edge weld and the tree build: 0.03 s each for the bunny
  report.boundsCut = !grid.outsidePrims.empty();
  report.rule =
      report.openEdges > 0 || report.leakyMethod || report.boundsCut ? FillRule::WindingNumber : FillRule::Enclosed;
  if (options.rule) report.rule = *options.rule;
  if (report.rule == FillRule::WindingNumber)
    winding = std::make_shared<const FillWinding>(scene, std::move(boundaries), grid);
  return report;
}

// Per gap: whether its component (the root `uf` gives it) is enclosed; `outsideRoot(root)` says it is not.
template <typename IsOutside>
std::vector<uint8_t> enclosedGaps(const RowTable& t, UnionFind& uf, const IsOutside& outsideRoot,
                                  const CancelCheck& check = {}) {
  std::vector<uint8_t> enclosed(t.gaps.size(), 0);
  for (uint64_t g = 0; g < t.gaps.size(); ++g) {
    check(g);
    enclosed[g] = !outsideRoot(uf.find(g + 1));
  }
  return enclosed;
}

// Under cut bounds (FillReport::boundsCut): the solid runs of the rows of [ownRows[0], ownRows[1]) that hold no
// occupied cell, which the table does not list (otherwise a row without a surface cell is outside by definition).
// Each is one empty run, decided as the fill decides its runs (decideRun, by winding number). A row whose line
// misses the (y, z) box of every primitive is outside: a surface lying in a half-space not holding the point has
// |w| < 1/2 there.
std::vector<CellRun> bareRowRuns(const Grid& grid, const FillWinding& winding, const RowTable& t,
                                 std::array<uint64_t, 2> ownRows, const FillOptions& options, FillReport& report) {
  const uint64_t nx = grid.dims[0], ny = grid.dims[1];
  const std::array<std::vector<double>, 3> centres = cellCentresByAxis(grid);
  // The bare rows in ascending order, a block at a time (each block's runs are sorted; blocks concatenate).
  const uint64_t count = ownRows[1] - ownRows[0];
  const uint64_t blockRows = 4096, blocks = (count + blockRows - 1) / blockRows;
  std::vector<std::vector<CellRun>> pieces(blocks);
  std::atomic<uint64_t> evaluations{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(uint64_t(0), blocks, [&](uint64_t b) {
    if (cancelled) return;
    const uint64_t lo = ownRows[0] + b * blockRows, hi = std::min(ownRows[1], lo + blockRows);
    size_t listed = size_t(std::lower_bound(t.row.begin(), t.row.end(), lo) - t.row.begin());
    uint64_t n = 0;
    for (uint64_t row = lo; row < hi; ++row) {
      while (listed < t.row.size() && t.row[listed] < row) ++listed;
      if (listed < t.row.size() && t.row[listed] == row) continue;
      const double y = centres[1][row % ny], z = centres[2][row / ny];
      if (y < winding.yzLo[0] || y > winding.yzHi[0] || z < winding.yzLo[1] || z > winding.yzHi[1]) continue;
      const Piece p = decideRun(0, uint32_t(nx - 1), [&](uint32_t x) {
        ++n;
        return std::abs(winding.scene.at({centres[0][x], y, z})) >= kWindingThreshold;
      });
      if (p.lo <= p.hi) pieces[b].push_back({row * nx + p.lo, uint64_t(p.hi) - p.lo + 1});
    }
    evaluations += n;
    if (options.progress && !options.progress(1)) cancelled = true;
  });
  if (cancelled) fail<Error>("solid fill cancelled");
  report.windingQueries += evaluations;
  std::vector<CellRun> runs;
  for (const auto& piece : pieces) runs.insert(runs.end(), piece.begin(), piece.end());
  return runs;
}

// Two sorted lists of disjoint runs merged into one, runs that touch joined.
std::vector<CellRun> mergeRuns(const std::vector<CellRun>& a, const std::vector<CellRun>& b) {
  std::vector<CellRun> out;
  out.reserve(a.size() + b.size());
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    const CellRun r = j == b.size() || (i < a.size() && a[i].first < b[j].first) ? a[i++] : b[j++];
    if (!out.empty() && out.back().first + out.back().count == r.first)
      out.back().count += r.count;
    else
      out.push_back(r);
  }
  return out;
}

// The solid runs of the table's rows from `firstRow` on, sorted and merged where they touch, under report.rule;
// adds their counts to `report`. The serial loops ask options.progress (the gather after the sweeps: 0.24 s at
// 2048^3 for the bunny).
std::vector<CellRun> solidRuns(const Grid& grid, const FillWinding* winding, const RowTable& t,
                               const std::vector<uint8_t>& enclosed, size_t firstRow, const FillOptions& options,
                               FillReport& report, std::array<uint64_t, 2> ownRows) {
  const CancelCheck before{&options, 0}, check{&options, 1};  // the fraction before the sweeps and after
  std::vector<CellRun> runs;
  uint64_t enclosedCells = 0;
  for (uint64_t g = t.gapBegin[firstRow]; g < t.gaps.size(); ++g) {
    before(g);
    if (enclosed[g]) enclosedCells += t.gaps[g].count;
  }
  if (report.rule == FillRule::Enclosed) {
    // The enclosed gaps are the runs, already sorted and never adjacent (occupied cells or a row end between
    // them): no per-run scratch needed.
    for (uint64_t g = t.gapBegin[firstRow]; g < t.gaps.size(); ++g) {
      check(g);
      if (enclosed[g]) runs.push_back(t.gaps[g]);
    }
    report.solidCells += enclosedCells;
    report.enclosedCells += enclosedCells;
    return runs;
  }
  std::vector<Piece> pieces = slotVector(t.gaps.size() + 2 * t.row.size(), Piece{}, CancelCheck{&options, 0});
  const auto [full, caps] = decideRuns(grid, winding, t, enclosed, options, firstRow, pieces);
  report.windingQueries += full;
  report.capQueries += caps;
  // Reserved once: growing a vector of millions of runs costs more in page faults than the loop itself.
  check();
  const uint64_t firstPiece = firstSlot(t, firstRow);
  runs.reserve(uint64_t(
      std::count_if(pieces.begin() + ptrdiff_t(firstPiece), pieces.end(), [](Piece p) { return p.lo <= p.hi; })));
  uint64_t solid = 0;
  for (size_t r = firstRow; r < t.row.size(); ++r) {
    check(r);
    const uint64_t base = t.row[r] * grid.dims[0];
    for (uint64_t s = firstSlot(t, r); s < firstSlot(t, r + 1); ++s) {
      const Piece p = pieces[s];
      if (p.lo > p.hi) continue;
      const uint64_t first = base + p.lo, count = uint64_t(p.hi) - p.lo + 1;
      solid += count;
      // A row's last run and the next row's first can touch: runs must stay non-adjacent.
      if (!runs.empty() && runs.back().first + runs.back().count == first)
        runs.back().count += count;
      else
        runs.push_back({first, count});
    }
  }
  if (report.boundsCut && winding) {
    std::vector<CellRun> bare = bareRowRuns(grid, *winding, t, ownRows, options, report);
    for (const CellRun& r : bare) solid += r.count;
    runs = mergeRuns(runs, bare);
  }
  if (options.windingOnly) enclosedCells = 0;
  report.solidCells += solid;
  report.enclosedCells += enclosedCells;
  report.windingCells += solid - enclosedCells;
  return runs;
}

// A slab's cells as a grid (the plane below the slab, then the slab's own), its rows and its flood components.
struct SlabLinks {
  Grid grid;
  RowTable table;
  UnionFind uf;
  size_t firstRow = 0;       // the first row of the slab's own planes
  uint64_t firstTopGap = 0;  // the first gap of its top plane
};

SlabLinks linkSlab(Grid&& grid, uint32_t k0, uint32_t k1, uint64_t memoryLimitBytes) {
  SlabLinks s{std::move(grid), {}, {}, 0, 0};
  const uint64_t ny = s.grid.dims[1], nz = s.grid.dims[2];
  s.table = buildRows(s.grid, memoryLimitBytes);
  s.uf = linkGaps(s.table, s.grid, PlaneRange{k0 > 0 ? k0 - 1u : 0u, k1 - 1u, k0 > 0, k1 < nz});
  const auto rowAt = [&](uint64_t plane) {
    return size_t(std::lower_bound(s.table.row.begin(), s.table.row.end(), plane * ny) - s.table.row.begin());
  };
  s.firstRow = rowAt(k0);
  s.firstTopGap = s.table.gapBegin[rowAt(k1 - 1u)];
  return s;
}
}  // namespace

static FillReport framedFillSolid(Grid& grid, const Scene& scene, const FillOptions& options);

// The winding numbers in the power-of-two frame of the scene and the bounds (docs/limits.md "Numeric domain"):
// at 2^400 their products overflowed and nothing was filled. Cells of subnormal width stay in world units, where
// their boundaries are computed (the frame would round them differently).
FillReport fillSolid(Grid& grid, const Scene& scene, const FillOptions& options) {
  const PowerOfTwoFrame frame = fractionFrame(scene, grid.bounds);
  bool useFrame = !frame.identity();
  for (int a = 0; a < 3; ++a) useFrame = useFrame && (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a] >= DBL_MIN;
  if (!useFrame) return framedFillSolid(grid, scene, options);
  const FramedBounds framed(grid, frame);
  return framedFillSolid(grid, sceneInFrame(scene, frame), options);
}

static FillReport framedFillSolid(Grid& grid, const Scene& scene, const FillOptions& options) {
  std::shared_ptr<const FillWinding> winding;
  const CancelCheck check{&options, 0};
  check();
  FillReport report = startFill(grid, scene, options, winding);
  check();
  report.emptyCells = grid.cellCount() - grid.occupiedCount();
  const RowTable table = buildRows(grid, options.memoryLimitBytes, check);
  std::vector<uint8_t> enclosed;
  {
    UnionFind uf = linkGaps(table, grid, {}, check);
    check();
    const uint64_t outside = uf.find(0);
    enclosed = enclosedGaps(
        table, uf, [&](uint64_t root) { return root == outside; }, check);
  }
  grid.solidRuns =
      solidRuns(grid, winding.get(), table, enclosed, 0, options, report, {0, uint64_t(grid.dims[1]) * grid.dims[2]});
  if (options.progress && !options.progress(1.0)) fail<Error>("solid fill cancelled");
  return report;
}

SlabFill::SlabFill(const Grid& plan, const Scene& scene, const FillOptions& options) : options_(options) {
  plan_.bounds = plan.bounds;
  plan_.dims = plan.dims;
  plan_.method = plan.method;
  plan_.outsidePrims = plan.outsidePrims;
  report_ = startFill(plan_, scene, options, winding_);
}

const std::vector<uint64_t>& SlabFill::labelsBelow() const {
  static const std::vector<uint64_t> none;  // the first slab: nothing below
  return slab_ > 0 ? topLabels_[slab_ - 1] : none;
}

Grid SlabFill::slabGrid(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1) {
  const uint64_t plane = uint64_t(plan_.dims[0]) * plan_.dims[1];
  if (k0 != nextPlane_ || k1 <= k0 || k1 > plan_.dims[2])
    fail<Error>("solid fill: slab of planes [", k0, ", ", k1, ") out of order (next plane ", nextPlane_, ")");
  if (!keys.empty() && (keys.front() < k0 * plane || keys.back() >= k1 * plane))
    fail<Error>("solid fill: a cell of the slab of planes [", k0, ", ", k1, ") lies outside it");
  Grid g = plan_;
  g.cellKeys.reserve(previousPlane_.size() + keys.size());
  g.cellKeys.assign(previousPlane_.begin(), previousPlane_.end());
  g.cellKeys.insert(g.cellKeys.end(), keys.begin(), keys.end());
  // The slab's top plane is the next slab's plane below.
  previousPlane_.assign(std::lower_bound(keys.begin(), keys.end(), (k1 - 1u) * plane), keys.end());
  nextPlane_ = k1;
  return g;
}

FillOptions SlabFill::slabOptions(uint32_t k0, uint32_t k1, bool secondPass) const {
  FillOptions o = options_;
  if (!options_.progress) return o;
  const double nz = plan_.dims[2], from = (secondPass ? nz : 0) + k0, width = k1 - k0;
  o.progress = [progress = options_.progress, from, width, nz](double f) {
    return progress((from + f * width) / (2 * nz));
  };
  return o;
}

void SlabFill::link(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1) {
  if (filling_) fail<Error>("solid fill: a slab linked after the fill began");
  SlabLinks s = linkSlab(slabGrid(keys, k0, k1), k0, k1, options_.memoryLimitBytes);
  const std::vector<uint64_t>& below = labelsBelow();
  if (s.table.gapBegin[s.firstRow] != below.size())
    fail<Error>("solid fill: the plane below slab [", k0, ", ", k1, ") is not the one linked before");
  UnionFind labels{std::move(labelParent_)};
  const uint64_t outside = s.uf.find(0);
  std::unordered_map<uint64_t, uint64_t> labelOf;  // component root -> its label
  for (uint64_t g = 0; g < below.size(); ++g) {
    const uint64_t root = s.uf.find(g + 1);
    if (root == outside)
      labels.unite(0, below[g]);
    else if (const auto [it, fresh] = labelOf.try_emplace(root, below[g]); !fresh)
      labels.unite(it->second, below[g]);
  }
  std::vector<uint64_t> top;
  if (k1 < plan_.dims[2]) {
    top.reserve(s.table.gaps.size() - s.firstTopGap);
    for (uint64_t g = s.firstTopGap; g < s.table.gaps.size(); ++g) {
      const uint64_t root = s.uf.find(g + 1);
      if (root == outside) {
        top.push_back(0);
        continue;
      }
      const auto [it, fresh] = labelOf.try_emplace(root, labels.parent.size());
      if (fresh) labels.parent.push_back(it->second);
      top.push_back(it->second);
    }
  }
  labelParent_ = std::move(labels.parent);
  topLabels_.push_back(std::move(top));
  ++slab_;
  if (options_.progress && !slabOptions(k0, k1, false).progress(1.0)) fail<Error>("solid fill cancelled");
}

std::vector<CellRun> SlabFill::fill(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1) {
  if (!filling_) {
    if (nextPlane_ != plan_.dims[2]) fail<Error>("solid fill: the fill began before every plane was linked");
    filling_ = true, slab_ = 0, nextPlane_ = 0;
    previousPlane_.clear();
    UnionFind labels{std::move(labelParent_)};
    for (uint64_t n = 0; n < labels.parent.size(); ++n) labels.find(n);  // compressed: a label's root is its parent
    labelParent_ = std::move(labels.parent);
  }
  if (slab_ >= topLabels_.size()) fail<Error>("solid fill: more slabs filled than linked");
  SlabLinks s = linkSlab(slabGrid(keys, k0, k1), k0, k1, options_.memoryLimitBytes);
  const std::vector<uint64_t>&below = labelsBelow(), &top = topLabels_[slab_];
  const uint64_t outside = s.uf.find(0);
  // A component is outside when it reaches the outside within the slab or through a labelled gap of a face plane.
  std::unordered_map<uint64_t, bool> outsideThroughLabel;
  for (uint64_t g = 0; g < below.size(); ++g) outsideThroughLabel[s.uf.find(g + 1)] = labelParent_[below[g]] == 0;
  for (uint64_t g = 0; g < top.size(); ++g)
    outsideThroughLabel[s.uf.find(s.firstTopGap + g + 1)] = labelParent_[top[g]] == 0;
  const std::vector<uint8_t> enclosed = enclosedGaps(s.table, s.uf, [&](uint64_t root) {
    if (root == outside) return true;
    const auto it = outsideThroughLabel.find(root);
    return it != outsideThroughLabel.end() && it->second;
  });
  report_.emptyCells += (k1 - k0) * uint64_t(plan_.dims[0]) * plan_.dims[1] - keys.size();
  std::vector<CellRun> runs =
      solidRuns(s.grid, winding_.get(), s.table, enclosed, s.firstRow, slabOptions(k0, k1, true), report_,
                {uint64_t(k0) * plan_.dims[1], uint64_t(k1) * plan_.dims[1]});
  ++slab_;
  if (options_.progress && !slabOptions(k0, k1, true).progress(1.0)) fail<Error>("solid fill cancelled");
  return runs;
}

std::string describeFill(const FillReport& r) {
  std::ostringstream out;
  if (r.rule == FillRule::Enclosed) {
    out << "closed surface, " << r.solidCells << " solid cells";
    return out.str();
  }
  out << "|winding number| >= " << kWindingThreshold << " (";
  const char* sep = "";
  if (r.openEdges > 0) out << "mesh has " << r.openEdges << " open edges", sep = "; ";
  if (r.leakyMethod) out << sep << "method center leaves gaps in surfaces", sep = "; ";
  if (r.boundsCut) out << sep << "the bounds cut the scene", sep = "; ";
  if (*sep == 0) out << "asked for: closed cavities stay empty";
  out << "), " << r.solidCells << " solid cells (" << r.enclosedCells << " enclosed, " << r.windingCells
      << " by winding number, " << r.windingQueries << " evaluations";
  if (r.capQueries > 0) out << ", " << r.capQueries << " of the hole caps alone";
  out << ")";
  return out.str();
}

std::string fillWarning(const FillReport& r) {
  // Under the flood fill a full grid is exact (a closed box on the grid's faces); under the winding number it more
  // likely means an inside-out or wrapping surface.
  // A closed mesh filled by winding number on request (--fraction) is as exact as the flood fill.
  const bool closed = r.openEdges == 0 && !r.leakyMethod;
  if (r.rule == FillRule::WindingNumber && !closed && r.emptyCells > 0 && r.solidCells == r.emptyCells)
    return "every empty cell of the grid is solid (by winding number): is the grid inside the surface?";
  if (r.emptyCells > 0 && r.solidCells == 0) return "no empty cell is inside a surface: nothing filled";
  return "";
}

}  // namespace vox
