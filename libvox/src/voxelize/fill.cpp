#include "vox/voxelize/fill.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <numbers>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "vox/core/error.h"
#include "vox/voxelize/open_edges.h"
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
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
  }
};

struct Interval {
  uint32_t lo, hi;  // x range, inclusive
  uint64_t node;    // linkGaps' union-find node: gap + 1, or 0 for a run that touches an x face (outside)
  uint64_t slot;    // the run's slot (firstSlot)
};

// Scratch bytes per listed row and per gap (row table, union-find, flags, solid pieces, the output runs at worst).
constexpr double kBytesPerRow = 24 + 16 + 16, kBytesPerGap = 16 + 8 + 1 + 8 + 16;

RowTable buildRows(const Grid& grid, uint64_t memoryLimitBytes) {
  const uint64_t nx = grid.dims[0];
  const auto& keys = grid.cellKeys;
  uint64_t rows = 0, gaps = 0;  // counted first so that the budget is checked before allocating
  for (size_t c = 0; c < keys.size(); ++c) {
    if (c == 0 || keys[c] / nx != keys[c - 1] / nx) ++rows;
    else if (keys[c] > keys[c - 1] + 1) ++gaps;
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
    if (a[p].hi < b[q].lo) ++p;
    else if (b[q].hi < a[p].lo) ++q;
    else {
      const int64_t la = label(a[p]), lb = label(b[q]);
      if (la >= 0 && lb >= 0) uf.unite(uint64_t(la), uint64_t(lb));
      if (a[p].hi < b[q].hi) ++p;
      else ++q;
    }
  }
}

// Face-connected groups of the runs that `keep` accepts, as a union-find over slots. Only listed rows are swept,
// so runs joined through a row without surface cells stay in separate groups (one more evaluation, never wrong).
template <typename Keep>
UnionFind linkRuns(const RowTable& t, const Grid& grid, const Keep& keep) {
  UnionFind uf;
  uf.parent.resize(t.gapBegin.back() + 2 * t.row.size());
  for (uint64_t n = 0; n < uf.parent.size(); ++n) uf.parent[n] = n;
  const uint64_t ny = grid.dims[1], nz = grid.dims[2];
  auto label = [&](const Interval& run) { return keep(run) ? int64_t(run.slot) : int64_t(-1); };
  size_t cursor[2] = {0, 0};
  std::vector<Interval> mine, theirs;
  for (size_t r = 0; r < t.row.size(); ++r) {
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

// 6-connected components of the empty cells, over runs: a gap is enclosed when its component does not reach
// the outside. Each pair of listed neighbouring rows is swept once, from the lower row; a neighbour that is not
// listed (or lies outside the grid) is all empty and outside.
UnionFind linkGaps(const RowTable& t, const Grid& grid) {
  UnionFind uf;
  uf.parent.resize(t.gaps.size() + 1);
  for (uint64_t n = 0; n < uf.parent.size(); ++n) uf.parent[n] = n;
  const uint64_t ny = grid.dims[1], nz = grid.dims[2];
  const int64_t offsets[4] = {-int64_t(ny), -1, 1, int64_t(ny)};
  size_t cursor[4] = {0, 0, 0, 0};  // per offset, first listed row >= target; targets only grow
  std::vector<Interval> mine, theirs;
  for (size_t r = 0; r < t.row.size(); ++r) {
    const uint64_t id = t.row[r], j = id % ny, k = id / ny;
    const bool hasGaps = t.gapBegin[r + 1] > t.gapBegin[r];
    bool loaded = false;
    for (int o = 0; o < 4; ++o) {
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
    // The fast value errs by about 1e-3 (winding_number.h); near the threshold it is recomputed more closely, so
    // that the decision is the exact one except where the exact value itself is within 1e-3 of the threshold.
    constexpr double kRefineMargin = 0.05, kRefineBeta = 8;
    double w = windingNumber(tree, q);
    if (std::abs(std::abs(w) - kWindingThreshold) < kRefineMargin) w = windingNumber(tree, q, kRefineBeta);
    for (const Sphere& s : spheres) {
      const Vec3 p = s.isEllipsoid() ? transformPoint(s.transform, q) : q;
      const Vec3 d = p - s.center;
      if (dot(d, d) < s.radius * s.radius) w += 1;
    }
    return w;
  }
};

Vec3 cellCentre(const Grid& grid, uint64_t key) {
  const auto ijk = cellIndex(grid.dims, key);
  Vec3 q;
  for (int a = 0; a < 3; ++a)
    q.at(a) = 0.5 * (cellBoundary(grid.bounds, grid.dims, a, ijk[a]) +
                     cellBoundary(grid.bounds, grid.dims, a, int64_t(ijk[a]) + 1));
  return q;
}

// A solid part [lo, hi] of an empty run, x indices within its row; empty when lo > hi.
struct Piece {
  uint32_t lo = 1, hi = 0;
};

// Decides one empty run by winding number. Its cells meet no surface, so the winding number changes along it
// continuously, and only near open edges: both end cells are evaluated; when they disagree the run is split where
// the decision changes (bisection, assuming one crossing).
Piece decideRun(const Grid& grid, const SceneWinding& winding, uint64_t rowBase, uint32_t lo, uint32_t hi,
                uint64_t& queries) {
  auto inside = [&](uint32_t x) {
    ++queries;
    return std::abs(winding.at(cellCentre(grid, rowBase + x))) >= kWindingThreshold;
  };
  const bool a = inside(lo), b = lo == hi ? a : inside(hi);
  if (a == b) return a ? Piece{lo, hi} : Piece{};
  uint32_t l = lo, h = hi;  // inside(l) == a, inside(h) == b
  while (h - l > 1) {
    const uint32_t m = l + (h - l) / 2;
    (inside(m) == a ? l : h) = m;
  }
  return a ? Piece{lo, l} : Piece{h, hi};
}

// Where runs may share one winding number. The winding number of a mesh with holes is that of the closed surface
// made by capping each hole (an integer, constant between surfaces) minus the caps' own winding numbers. Cap each
// boundary by the cone from its box centre (inside its box, OpenBoundary::capArea); seen from a distance d of that
// box a cap's winding number is at most capArea / (4 pi d^2). Runs where the sum of these bounds is at most kFar,
// joined face to face, have winding numbers within 2 kFar of each other: one evaluation decides a whole group when
// it lies farther than 2 kFar from the threshold. Runs nearer the holes are evaluated one by one.
struct Sharing {
  bool enabled = false;
  std::vector<OpenBoundary> boundaries;
  static constexpr double kFar = 0.2;
  static constexpr size_t kMaxBoundaries = 64;  // more: a soup, where every run is evaluated

  Sharing(const Scene& scene, bool leaky) {
    // Gaps in a `center` surface join cells on both sides of it: no constant winding number between them.
    if (leaky) return;
    boundaries = openBoundaries(scene.triangles);
    enabled = boundaries.size() <= kMaxBoundaries;
  }
  bool far(const Box& run) const {
    double bound = 0;
    for (const OpenBoundary& b : boundaries) {
      double d2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double gap = std::max({b.bounds.lo[a] - run.hi[a], run.lo[a] - b.bounds.hi[a], 0.0});
        d2 += gap * gap;
      }
      if (d2 == 0) return false;
      bound += b.capArea / (4 * std::numbers::pi * d2);
    }
    return bound <= kFar;
  }
};

Box runBox(const Grid& grid, uint64_t rowBase, const Interval& run) {
  const auto lo = cellIndex(grid.dims, rowBase + run.lo);
  Box b = cellBox(grid, lo[0], lo[1], lo[2]);
  b.hi.x = cellBoundary(grid.bounds, grid.dims, 0, int64_t(run.hi) + 1);
  return b;
}

// Per slot: what the winding stage must do with it.
enum SlotState : uint8_t { kNone = 0, kShared = 1, kDecided = 2 };

// The solid part of every empty run of the listed rows: enclosed gaps whole; under the WindingNumber rule the other
// runs by decideRun, or, far from every open edge, by one evaluation per face-connected group (Sharing). Returns the
// winding numbers evaluated.
uint64_t decideRuns(const Grid& grid, const Scene& scene, const RowTable& t, const std::vector<uint8_t>& enclosed,
                    bool winding, const FillOptions& options, std::vector<Piece>& pieces) {
  std::optional<SceneWinding> w;
  std::optional<Sharing> sharing;
  if (winding) w.emplace(scene), sharing.emplace(scene, grid.method == OverlapMethod::Center);
  std::vector<uint8_t> state(pieces.size(), kNone);
  std::atomic<uint64_t> done{0}, queries{0};
  std::atomic<bool> cancelled{false};
  const uint64_t steps = 2 * t.row.size();
  auto forRows = [&](auto&& body) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, t.row.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
      if (cancelled) return;
      std::vector<Interval> runs;
      uint64_t evaluated = 0;
      for (size_t r = range.begin(); r < range.end(); ++r) {
        rowIntervals(t, grid, r, runs);
        for (const Interval& run : runs) body(r, run, evaluated);
      }
      queries += evaluated;
      const uint64_t finished = done += range.size();
      if (options.progress && !options.progress(double(finished) / double(steps))) cancelled = true;
    });
    if (cancelled) fail<Error>("solid fill cancelled");
  };
  const uint64_t nx = grid.dims[0];
  // Pass 1: enclosed gaps, and runs near open edges decided one by one; the others wait for their group.
  forRows([&](size_t r, const Interval& run, uint64_t& evaluated) {
    if (run.node && enclosed[run.node - 1] && !options.windingOnly) {
      pieces[run.slot] = {run.lo, run.hi};
      state[run.slot] = kDecided;
    } else if (winding) {
      if (sharing->enabled && sharing->far(runBox(grid, t.row[r] * nx, run))) {
        state[run.slot] = kShared;
      } else {
        pieces[run.slot] = decideRun(grid, *w, t.row[r] * nx, run.lo, run.hi, evaluated);
        state[run.slot] = kDecided;
      }
    }
  });
  if (!winding || !sharing->enabled) return queries;
  // Groups of shared runs, then one evaluation per group at its root run (the first cell of the group's root).
  UnionFind groups = linkRuns(t, grid, [&](const Interval& run) { return state[run.slot] == kShared; });
  struct Root {
    uint64_t slot, key;  // key: the middle cell of the root run
  };
  std::vector<Root> roots;
  std::vector<Interval> runs;
  for (size_t r = 0; r < t.row.size(); ++r) {
    rowIntervals(t, grid, r, runs);
    for (const Interval& run : runs)
      if (state[run.slot] == kShared && groups.findConst(run.slot) == run.slot)
        roots.push_back({run.slot, t.row[r] * nx + run.lo + (run.hi - run.lo) / 2});
  }
  std::vector<int8_t> verdict(state.size(), -1);  // at roots: 1 inside, 0 outside, -1 too close to call
  tbb::parallel_for(size_t(0), roots.size(), [&](size_t i) {
    const double v = std::abs(w->at(cellCentre(grid, roots[i].key)));
    if (std::abs(v - kWindingThreshold) > 2 * Sharing::kFar) verdict[roots[i].slot] = v >= kWindingThreshold;
  });
  queries += roots.size();
  // Pass 2: a shared run takes its group's verdict, or is evaluated alone when the verdict was too close to call.
  forRows([&](size_t r, const Interval& run, uint64_t& evaluated) {
    if (state[run.slot] != kShared) return;
    const int8_t v = verdict[groups.findConst(run.slot)];
    if (v < 0) pieces[run.slot] = decideRun(grid, *w, t.row[r] * nx, run.lo, run.hi, evaluated);
    else if (v == 1) pieces[run.slot] = {run.lo, run.hi};
  });
  return queries;
}

}  // namespace

FillReport fillSolid(Grid& grid, const Scene& scene, const FillOptions& options) {
  FillReport report;
  report.emptyCells = grid.cellCount() - grid.occupiedCount();
  report.leakyMethod = grid.method == OverlapMethod::Center;
  const double treeBytes = 400.0 * double(scene.triangles.size());  // tree, its build and the edge count
  if (treeBytes > double(options.memoryLimitBytes))
    fail<LimitError>("solid fill of ", scene.triangles.size(), " triangles needs about ",
                     uint64_t(treeBytes / (1 << 20)), " MiB of scratch memory, more than the ",
                     options.memoryLimitBytes >> 20, " MiB allowed");
  report.openEdges = countOpenEdges(scene.triangles);
  report.rule = report.openEdges > 0 || report.leakyMethod ? FillRule::WindingNumber : FillRule::Enclosed;
  if (options.rule) report.rule = *options.rule;

  const RowTable table = buildRows(grid, options.memoryLimitBytes);
  std::vector<uint8_t> enclosed(table.gaps.size(), 0);
  {
    UnionFind uf = linkGaps(table, grid);
    const uint64_t outside = uf.find(0);
    for (uint64_t g = 0; g < table.gaps.size(); ++g) enclosed[g] = uf.find(g + 1) != outside;
  }
  grid.solidRuns.clear();
  if (report.rule == FillRule::Enclosed) {
    // The enclosed gaps are the runs, already sorted and never adjacent (occupied cells or a row end between
    // them): no per-run scratch needed.
    for (uint64_t g = 0; g < table.gaps.size(); ++g)
      if (enclosed[g]) {
        grid.solidRuns.push_back(table.gaps[g]);
        report.solidCells += table.gaps[g].count;
      }
    report.enclosedCells = report.solidCells;
    if (options.progress) options.progress(1.0);
    return report;
  }
  std::vector<Piece> pieces(table.gaps.size() + 2 * table.row.size());
  report.windingQueries = decideRuns(grid, scene, table, enclosed, report.rule == FillRule::WindingNumber, options,
                                     pieces);
  grid.solidRuns.clear();
  for (size_t r = 0; r < table.row.size(); ++r) {
    const uint64_t base = table.row[r] * grid.dims[0];
    for (uint64_t s = firstSlot(table, r); s < firstSlot(table, r + 1); ++s) {
      const Piece p = pieces[s];
      if (p.lo > p.hi) continue;
      const uint64_t first = base + p.lo, count = uint64_t(p.hi) - p.lo + 1;
      report.solidCells += count;
      // A row's last run and the next row's first can touch: runs must stay non-adjacent.
      if (!grid.solidRuns.empty() && grid.solidRuns.back().first + grid.solidRuns.back().count == first)
        grid.solidRuns.back().count += count;
      else
        grid.solidRuns.push_back({first, count});
    }
  }
  for (uint64_t g = 0; g < table.gaps.size(); ++g)
    if (enclosed[g] && !options.windingOnly) report.enclosedCells += table.gaps[g].count;
  report.windingCells = report.solidCells - report.enclosedCells;
  if (options.progress) options.progress(1.0);
  return report;
}

std::string describeFill(const FillReport& r) {
  std::ostringstream out;
  if (r.rule == FillRule::Enclosed) {
    out << "closed surface, " << r.solidCells << " solid cells";
    return out.str();
  }
  out << "|winding number| >= " << kWindingThreshold << " (";
  if (r.openEdges > 0) out << "mesh has " << r.openEdges << " open edges";
  if (r.openEdges > 0 && r.leakyMethod) out << "; ";
  if (r.leakyMethod) out << "method center leaves gaps in surfaces";
  out << "), " << r.solidCells << " solid cells (" << r.enclosedCells << " enclosed, " << r.windingCells
      << " by winding number, " << r.windingQueries << " evaluations)";
  return out.str();
}

std::string fillWarning(const FillReport& r) {
  // Under the flood fill a full grid is exact (a closed box on the grid's faces); under the winding number it more
  // likely means an inside-out or wrapping surface.
  if (r.rule == FillRule::WindingNumber && r.emptyCells > 0 && r.solidCells == r.emptyCells)
    return "every empty cell of the grid is solid (by winding number): is the grid inside the surface?";
  if (r.emptyCells > 0 && r.solidCells == 0)
    return "no empty cell is inside a surface: nothing filled";
  return "";
}

}  // namespace vox
