#include "vox/voxelize/voxelize.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <span>

#include "vox/core/cell_range.h"
#include "vox/core/huge_pages.h"
#include "voxelize/radix_sort.h"
#include "voxelize/triangle_filter.h"
#include "vox/core/error.h"
#include "vox/core/exact_number.h"
#include "vox/voxelize/overlap.h"

namespace vox {

namespace {

Box paddedBounds(Box b) {
  const Vec3 extent = b.hi - b.lo;
  const double largest = std::max({extent.x, extent.y, extent.z});
  for (int a = 0; a < 3; ++a) {
    if (b.hi[a] > b.lo[a]) continue;
    // A flat scene still needs cells across its thin axis: pad by 1% of the largest extent (or 0.5 for a point),
    // but at least enough ulps that lo < hi holds far from the origin.
    double pad = largest > 0 ? 0.01 * largest : 0.5;
    pad = std::max(pad, 4 * std::fabs(b.lo[a]) * DBL_EPSILON + DBL_MIN);
    b.lo.at(a) -= pad;
    b.hi.at(a) += pad;
  }
  return b;
}

// The boundary formula b(i) = lo + (hi - lo) * i / n need not give b(n) == hi in floating point, which would leave a
// sliver of the bounds (and primitives lying on the top face) outside every cell. Nudge hi up by ulps until the
// formula reproduces it exactly; the change is a few ulps at most.
// Bounds the user gave make a failure a usage error; bounds taken from the scene make it the scene's (exit 2).
template <typename E>
void alignUpperBounds(Grid& grid) {
  for (int a = 0; a < 3; ++a) {
    int steps = 0;
    while (cellBoundary(grid.bounds, grid.dims, a, grid.dims[a]) != grid.bounds.hi[a]) {
      grid.bounds.hi.at(a) = std::nextafter(grid.bounds.hi[a], HUGE_VAL);
      if (++steps > 4096)
        fail<E>("bounds [", exactNumber(grid.bounds.lo[a]), ", ", exactNumber(grid.bounds.hi[a]), "] on axis ",
                "xyz"[a], " cannot be divided into ", grid.dims[a],
                " cells in double precision (coordinates of very "
                "different magnitudes?)");
    }
  }
}

void checkDims(const std::array<uint32_t, 3>& dims) {
  for (uint32_t n : dims)
    if (n == 0 || n > kMaxCellsPerAxis)
      fail<UsageError>("grid dimension ", n, " out of range (1 to ", kMaxCellsPerAxis, " cells per axis)");
}

// Cells a primitive may touch, from its bounding box; nullopt when the box misses the grid.
struct CellRange {
  std::array<int64_t, 3> first, last;
  uint64_t count() const {
    return uint64_t(last[0] - first[0] + 1) * uint64_t(last[1] - first[1] + 1) * uint64_t(last[2] - first[2] + 1);
  }
};

std::optional<CellRange> rangeOf(const Grid& grid, const Box& box) {
  CellRange r;
  for (int a = 0; a < 3; ++a) {
    const auto [f, l] = cellRange(grid.bounds, grid.dims, a, box.lo[a], box.hi[a]);
    if (f > l) return std::nullopt;
    r.first[a] = f;
    r.last[a] = l;
  }
  return r;
}

// The part of a primitive's cell range inside a brick's window (the whole grid for a single grid).
std::optional<CellRange> clip(std::optional<CellRange> r, const CellWindow& window) {
  if (!r) return r;
  for (int a = 0; a < 3; ++a) {
    r->first[a] = std::max<int64_t>(r->first[a], window.first[a]);
    r->last[a] = std::min<int64_t>(r->last[a], int64_t(window.end[a]) - 1);
    if (r->first[a] > r->last[a]) return std::nullopt;
  }
  return r;
}

// The bounded primitive ids to voxelize: all of them (ids 0 .. count-1) or a brick's candidates.
struct PrimitiveList {
  const uint32_t* list = nullptr;  // null: the identity
  size_t count = 0;
  size_t size() const { return count; }
  size_t operator[](size_t n) const { return list ? list[n] : n; }
};

bool inside(const Box& inner, const Box& outer) {
  for (int a = 0; a < 3; ++a)
    if (inner.lo[a] < outer.lo[a] || inner.hi[a] > outer.hi[a]) return false;
  return true;
}

// Cells of a row (fixed indices on two axes) that a triangle's plane can reach: the triangle's cells lie within a
// cell of its plane, so only those need the overlap test. The sweep axis is the normal's dominant one. The range is
// widened by a margin far above the rounding error of the computed normal (and the plane is not used at all when
// that normal is too uncertain), so the pruning never drops a cell the full test would take.
struct PlaneSweep {
  int axis = 0;
  bool usable = false;
  Vec3 n, origin;
  double margin = 0;

  PlaneSweep(const TriangleFilter& f, const Triangle& t, const Box& triBox)
      : n{f.normal[0], f.normal[1], f.normal[2]}, origin(t.v[0]) {
    const Vec3 an{std::fabs(n.x), std::fabs(n.y), std::fabs(n.z)};
    axis = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    const double na = an[axis];
    const double relErr = (f.normalErr[0] + f.normalErr[1] + f.normalErr[2]) / na;
    if (!(na > 0) || !(relErr < 1e-6) || !f.usable) return;
    const double diag = length(triBox.hi - triBox.lo);
    margin = 1e-4 * diag + 1e-12 * (std::fabs(origin.x) + std::fabs(origin.y) + std::fabs(origin.z));
    usable = true;
  }

  // Interval on `axis` of the plane over the rectangle [b0, b1] x [c0, c1] of the other two axes, widened.
  std::pair<double, double> range(double b0, double b1, double c0, double c1) const {
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    const double kb = -n[b] / n[axis], kc = -n[c] / n[axis];
    const double pb0 = kb * (b0 - origin[b]), pb1 = kb * (b1 - origin[b]);
    const double pc0 = kc * (c0 - origin[c]), pc1 = kc * (c1 - origin[c]);
    const double lo = origin[axis] + std::min(pb0, pb1) + std::min(pc0, pc1);
    const double hi = origin[axis] + std::max(pb0, pb1) + std::max(pc0, pc1);
    const double m = margin + 1e-9 * (std::fabs(lo) + std::fabs(hi));
    return {lo - m, hi + m};
  }
};

double triangleArea(const Triangle& t) { return 0.5 * length(cross(t.v[1] - t.v[0], t.v[2] - t.v[0])); }

// A generous estimate of the references a primitive makes: a surface of area A crosses at most about
// 3 A / h^2 + 2 P / h + 8 cells of side h (h the smallest cell side), and never more than its bounding range.
// `progress` (may be empty) is asked at 0 every 4096th primitive: a serial loop, 0.3 s for 6.5 million triangles.
double estimateReferences(const Scene& scene, const Grid& grid, const CellWindow& window, const PrimitiveList& ids,
                          const std::function<bool(double)>& progress = {}) {
  double h = HUGE_VAL;
  for (int a = 0; a < 3; ++a) h = std::min(h, (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a]);
  double total = 0;
  // bbox takes the whole range; center takes the cells whose centres lie in the footprint, at most the range too.
  const bool wholeRange = grid.method == OverlapMethod::BBox || grid.method == OverlapMethod::Center;
  auto add = [&](const Box& box, double area, double perimeter) {
    const auto r = clip(rangeOf(grid, box), window);
    if (!r) return;
    const double range = double(r->count());
    total += wholeRange ? range : std::min(range, 3 * area / (h * h) + 2 * perimeter / h + 8);
  };
  const size_t nTri = scene.triangles.size();
  for (size_t n = 0; n < ids.size(); ++n) {
    if (progress && (n & 4095) == 0 && !progress(0)) fail<Error>("voxelization cancelled");
    const size_t id = ids[n];
    if (id < nTri) {
      const Triangle& t = scene.triangles[id];
      add(triangleBounds(t), triangleArea(t),
          length(t.v[1] - t.v[0]) + length(t.v[2] - t.v[1]) + length(t.v[0] - t.v[2]));
    } else {
      const Box b = sphereBounds(scene.spheres[id - nTri]);
      const Vec3 e = (b.hi - b.lo) * 0.5;
      add(b, 4 * M_PI * std::max({e.x * e.y, e.y * e.z, e.x * e.z}), 0);
    }
  }
  return total;
}

struct PrimitiveList;
void voxelizeWindow(const Scene& scene, Grid& grid, const CellWindow& window, const PrimitiveList& ids,
                    const VoxelizeOptions& options, VoxelizeStats* stats);

}  // namespace

namespace {
// The bounds' extents divided by the largest one (each in (0, 1]).
Vec3 relativeExtents(const Box& bounds) {
  const Vec3 e = bounds.hi - bounds.lo;
  const double largest = std::max({e.x, e.y, e.z});
  return {e.x / largest, e.y / largest, e.z / largest};
}
}  // namespace

std::array<uint32_t, 3> dimsForResolution(const Box& bounds, uint32_t resolution) {
  if (resolution == 0 || resolution > kMaxCellsPerAxis)
    fail<UsageError>("resolution ", resolution, " out of range (1 to ", kMaxCellsPerAxis, ")");
  // Extents relative to the largest, so that bounds of subnormal width cannot underflow the cell size to 0.
  const Vec3 e = relativeExtents(bounds);
  std::array<uint32_t, 3> dims;
  for (int a = 0; a < 3; ++a) dims[a] = uint32_t(std::clamp<double>(std::round(e[a] * resolution), 1, resolution));
  return dims;
}

std::array<uint32_t, 3> defaultDims(const Box& bounds, size_t boundedPrimitives) {
  const Vec3 e = relativeExtents(bounds);
  const double target = std::max(1.0, kCellsPerPrimitive * double(boundedPrimitives));
  const double cell = std::cbrt(e.x * e.y * e.z / target);
  std::array<uint32_t, 3> dims;
  for (int a = 0; a < 3; ++a) dims[a] = uint32_t(std::clamp<double>(std::round(e[a] / cell), 1, 1024));
  return dims;
}

Grid planGrid(const Scene& scene, const VoxelizeOptions& options) {
  Grid grid;
  grid.method = options.method;
  if (options.bounds) {
    const Box& b = *options.bounds;
    if (!isFinite(b.lo) || !isFinite(b.hi)) fail<UsageError>("bounds must be finite numbers");
    for (int a = 0; a < 3; ++a)
      if (!(b.lo[a] < b.hi[a])) fail<UsageError>("bounds: minimum must be below maximum on every axis");
    grid.bounds = b;
  } else if (const auto b = sceneBounds(scene)) {
    grid.bounds = paddedBounds(*b);
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(grid.bounds.hi[a] - grid.bounds.lo[a]))
        fail<InputError>("scene bounds [", exactNumber(grid.bounds.lo[a]), ", ", exactNumber(grid.bounds.hi[a]),
                         "] on axis ", "xyz"[a], " are wider than the largest double: no grid can divide them");
  } else {
    grid.bounds = {{0, 0, 0}, {1, 1, 1}};
    grid.dims = {1, 1, 1};
    return grid;  // 0 + (1 - 0) * 1 / 1 == 1: already aligned
  }
  if (options.dims) {
    grid.dims = *options.dims;
  } else if (options.resolution) {
    grid.dims = dimsForResolution(grid.bounds, *options.resolution);
  } else {
    grid.dims = defaultDims(grid.bounds, scene.boundedCount());
  }
  checkDims(grid.dims);
  if (options.bounds)
    alignUpperBounds<UsageError>(grid);
  else
    alignUpperBounds<InputError>(grid);
  return grid;
}

std::vector<uint32_t> primitivesOutside(const Scene& scene, const Grid& grid) {
  std::vector<uint32_t> out;
  const size_t nTri = scene.triangles.size(), nBounded = scene.boundedCount();
  for (size_t id = 0; id < nBounded; ++id) {
    const Box b = id < nTri ? triangleBounds(scene.triangles[id]) : sphereBounds(scene.spheres[id - nTri]);
    if (!inside(b, grid.bounds)) out.push_back(uint32_t(id));
  }
  return out;
}

Grid voxelizeScene(const Scene& scene, const VoxelizeOptions& options, VoxelizeStats* stats) {
  Grid grid = planGrid(scene, options);
  const size_t nBounded = scene.boundedCount();
  if (nBounded == 0) return grid;
  if (nBounded > UINT32_MAX) fail<LimitError>("too many primitives (", nBounded, ")");
  if (options.bounds) grid.outsidePrims = primitivesOutside(scene, grid);
  voxelizeWindow(scene, grid, CellWindow{{0, 0, 0}, grid.dims}, PrimitiveList{nullptr, nBounded}, options, stats);
  return grid;
}

Grid voxelizeBrick(const Scene& scene, const Grid& plan, const CellWindow& window, std::span<const uint32_t> ids,
                   const VoxelizeOptions& options, VoxelizeStats* stats) {
  Grid grid = plan;
  grid.cellKeys.clear();
  grid.cellStart.assign(1, 0);
  grid.primIds.clear();
  for (int a = 0; a < 3; ++a)
    if (window.first[a] >= window.end[a] || window.end[a] > plan.dims[a])
      fail<UsageError>("brick window outside the grid on axis ", "xyz"[a]);
  if (scene.boundedCount() > UINT32_MAX) fail<LimitError>("too many primitives (", scene.boundedCount(), ")");
  for (uint32_t id : ids)
    if (id >= scene.boundedCount()) fail<UsageError>("brick candidate ", id, " is not a bounded primitive");
  if (ids.empty()) return grid;
  voxelizeWindow(scene, grid, window, PrimitiveList{ids.data(), ids.size()}, options, stats);
  return grid;
}

namespace {

// One thread's references (packed key << primBits | id when key and id fit 64 bits, else pairs) and counters.
struct Local {
  HugeVector<uint64_t> packedRefs;
  std::vector<std::pair<uint64_t, uint32_t>> pairRefs;
  uint64_t tested = 0, fallbacks = 0, degenerate = 0;
};

// The sorted packed references as grid's cell lists (grid's arrays empty, reserved): the array cut into chunks
// that begin where a cell begins, each chunk's cells counted and then written by one task, so that both threads
// gather (on one thread this loop was a fifth of the serial time left in a 1024^3 voxelization).
void gatherSorted(const uint64_t* sorted, size_t n, int primBits, Grid& grid, const std::function<void()>& check) {
  const uint64_t primMask = (uint64_t(1) << primBits) - 1;
  const size_t chunks = std::clamp<size_t>(n >> 16, 1, 256);
  std::vector<size_t> begin(chunks + 1, n);
  for (size_t c = 0; c < chunks; ++c) {
    size_t i = std::max(n / chunks * c, c > 0 ? begin[c - 1] : 0);
    while (i > 0 && i < n && (sorted[i] >> primBits) == (sorted[i - 1] >> primBits)) ++i;
    begin[c] = i;
  }
  auto startsCell = [&](size_t i, size_t first) {
    return i == first || (sorted[i] >> primBits) != (sorted[i - 1] >> primBits);
  };
  std::vector<size_t> cellsBefore(chunks + 1, 0);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    check();
    size_t cells = 0;
    for (size_t i = begin[c]; i < begin[c + 1]; ++i) cells += startsCell(i, begin[c]);
    cellsBefore[c + 1] = cells;
  });
  for (size_t c = 0; c < chunks; ++c) cellsBefore[c + 1] += cellsBefore[c];
  const size_t cells = cellsBefore[chunks];
  grid.cellKeys.resize(cells);
  grid.cellStart.resize(cells + 1);
  grid.primIds.resize(n);
  check();
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    check();
    size_t cell = cellsBefore[c];
    for (size_t i = begin[c]; i < begin[c + 1]; ++i) {
      if (startsCell(i, begin[c])) {
        grid.cellKeys[cell] = sorted[i] >> primBits;
        grid.cellStart[cell++] = i;
      }
      grid.primIds[i] = uint32_t(sorted[i] & primMask);
    }
  });
  grid.cellStart[cells] = n;
}

// Gathers the references of all threads into grid's compressed cell lists, grouped by cell in key order with ids
// ascending; returns the summed counters (seconds not set). `check` throws to cancel; it is called between the
// sort's and the gather's tasks (at 2048^3 this phase takes most of a second).
VoxelizeStats gatherReferences(tbb::enumerable_thread_specific<Local>& locals, bool packed, int primBits, int keyBits,
                               Grid& grid, const std::function<void()>& check) {
  VoxelizeStats local{};
  size_t total = 0;
  for (auto& l : locals) {
    total += packed ? l.packedRefs.size() : l.pairRefs.size();
    local.cellsTested += l.tested;
    local.exactFallbacks += l.fallbacks;
    local.degenerateTriangles += l.degenerate;
  }
  grid.cellKeys.clear();
  grid.cellStart.clear();
  grid.primIds.clear();
  // Sized once, never grown (a grown array is copied and faulted in again): a cell holds at least one reference, so
  // `total` bounds the cells. Capacity past the cells is address space only: untouched pages take no memory.
  grid.primIds.reserve(total);
  grid.cellKeys.reserve(total);
  grid.cellStart.reserve(total + 1);
  if (packed) {
    std::vector<std::span<const uint64_t>> parts;
    for (auto& l : locals) parts.emplace_back(l.packedRefs);
    const auto [sorted, n] = radixSortParts(parts, primBits + keyBits, kParallelSortFrom, check);
    for (auto& l : locals) HugeVector<uint64_t>().swap(l.packedRefs);
    check();
    gatherSorted(sorted.get(), n, primBits, grid, check);
    return local;
  }
  std::vector<std::pair<uint64_t, uint32_t>> all;
  all.reserve(total);
  for (auto& l : locals) {
    all.insert(all.end(), l.pairRefs.begin(), l.pairRefs.end());
    std::vector<std::pair<uint64_t, uint32_t>>().swap(l.pairRefs);
  }
  tbb::parallel_sort(all.begin(), all.end());
  for (const auto& [key, prim] : all) {
    if (grid.cellKeys.empty() || grid.cellKeys.back() != key) {
      grid.cellKeys.push_back(key);
      grid.cellStart.push_back(grid.primIds.size());
    }
    grid.primIds.push_back(prim);
  }
  grid.cellStart.push_back(grid.primIds.size());
  return local;
}

// What the voxelization of every primitive of a window reads: the scene, the planned grid and its cell boundaries,
// the window, the method, and how a reference is stored.
struct WindowContext {
  WindowContext(const Scene& scene_, const Grid& grid_, const CellWindow& window_, const VoxelizeOptions& options_)
      : scene(scene_),
        grid(grid_),
        window(window_),
        options(options_),
        dims(grid_.dims),
        nTri(scene_.triangles.size()),
        primBits(std::max(1, int(std::bit_width(uint64_t(scene_.boundedCount() - 1))))),
        keyBits(int(std::bit_width(grid_.cellCount() - 1))),
        packed(primBits + keyBits <= 64) {
    for (int a = 0; a < 3; ++a) {
      boundary[a].resize(size_t(dims[a]) + 1);
      for (int64_t i = 0; i <= int64_t(dims[a]); ++i) boundary[a][i] = cellBoundary(grid.bounds, dims, a, i);
      boundaryScale[a] = double(dims[a]) / (grid.bounds.hi[a] - grid.bounds.lo[a]);
    }
  }
  const Scene& scene;
  const Grid& grid;
  const CellWindow& window;
  const VoxelizeOptions& options;
  const std::array<uint32_t, 3> dims;
  const size_t nTri;
  const int primBits, keyBits;
  const bool packed;                            // references as key << primBits | id (else pairs)
  std::array<std::vector<double>, 3> boundary;  // cellBoundary(grid.bounds, dims, a, i) for i in [0, dims[a]]
  std::array<double, 3> boundaryScale;          // cells per unit: a first guess of a cell index
  // Primitives done of `nWork`, for checkCancel's fraction (voxelizeWindow counts them).
  mutable std::atomic<size_t> done{0};
  size_t nWork = 1;

  // Asked every kCancelCells cells of one primitive's cell loop: a ball or a bbox at 1000^3 is one primitive of up
  // to 10^9 cells, seconds between the block reports. Throws once the progress callback says stop.
  static constexpr uint32_t kCancelCells = 1 << 16;
  void checkCancel() const {
    if (options.progress && !options.progress(0.9 * double(done.load(std::memory_order_relaxed)) / double(nWork)))
      fail<Error>("voxelization cancelled");
  }

  Box cellBox(int64_t i, int64_t j, int64_t k) const {
    return Box{{boundary[0][i], boundary[1][j], boundary[2][k]},
               {boundary[0][i + 1], boundary[1][j + 1], boundary[2][k + 1]}};
  }
  void emit(Local& local, size_t id, int64_t i, int64_t j, int64_t k) const {
    const uint64_t key = cellKey(dims, i, j, k);
    if (packed)
      local.packedRefs.push_back((key << primBits) | id);
    else
      local.pairRefs.emplace_back(key, uint32_t(id));
  }
};

// Calls f(i, j, k) for every cell of `range`, x fastest.
template <typename F>
void forEachCell(const WindowContext& ctx, const CellRange& range, F&& f) {
  uint32_t n = 0;
  for (int64_t k = range.first[2]; k <= range.last[2]; ++k)
    for (int64_t j = range.first[1]; j <= range.last[1]; ++j)
      for (int64_t i = range.first[0]; i <= range.last[0]; ++i) {
        if (++n == WindowContext::kCancelCells) {
          n = 0;
          ctx.checkCancel();
        }
        f(i, j, k);
      }
}

// OverlapMethod::Center, the course's quick test: the cell's centre inside the footprint (the triangle's bounding
// box, or the sphere itself).
void centerCells(const WindowContext& ctx, size_t id, const Box& primBox, const CellRange& range, Local& local) {
  const bool isTri = id < ctx.nTri;
  Mat4 toObject;
  if (!isTri) toObject = inverse(ctx.scene.spheres[id - ctx.nTri].transform);
  forEachCell(ctx, range, [&](int64_t i, int64_t j, int64_t k) {
    const Box b = ctx.cellBox(i, j, k);
    const Vec3 c = (b.lo + b.hi) * 0.5;
    bool take;
    if (isTri) {
      take = c.x >= primBox.lo.x && c.x <= primBox.hi.x && c.y >= primBox.lo.y && c.y <= primBox.hi.y &&
             c.z >= primBox.lo.z && c.z <= primBox.hi.z;
    } else {
      const Sphere& s = ctx.scene.spheres[id - ctx.nTri];
      const Vec3 d = transformPoint(toObject, c) - s.center;
      take = dot(d, d) <= s.radius * s.radius;
    }
    if (take) ctx.emit(local, id, i, j, k);
  });
}

// A sphere's cells by the separating axes (sat) or the filtered exact test.
void sphereCells(const WindowContext& ctx, size_t id, const CellRange& range, Local& local) {
  const Sphere& s = ctx.scene.spheres[id - ctx.nTri];
  forEachCell(ctx, range, [&](int64_t i, int64_t j, int64_t k) {
    bool fallback = false;
    const bool hit = ctx.options.method == OverlapMethod::Sat ? sphereBoxSat(s, ctx.cellBox(i, j, k))
                                                              : sphereBoxFiltered(s, ctx.cellBox(i, j, k), &fallback);
    local.fallbacks += fallback;
    if (hit) ctx.emit(local, id, i, j, k);
  });
}

// The triangle's filter, its error bounds from |corner - origin| over every cell of the triangle's whole cell range
// (rounded up generously), not the window's part of it: the same bounds give the same undecided cells in every
// brick.
TriangleFilter preparedFilter(const WindowContext& ctx, const Triangle& t, const CellRange& fullRange) {
  TriangleFilter filter(t);
  double qMax[3];
  for (int ax = 0; ax < 3; ++ax)
    qMax[ax] = 1.0000001 * std::max(std::fabs(ctx.boundary[ax][fullRange.first[ax]] - filter.origin[ax]),
                                    std::fabs(ctx.boundary[ax][fullRange.last[ax] + 1] - filter.origin[ax]));
  filter.prepare(qMax);
  return filter;
}

// The cells of one row of `range` along the sweep's axis a (idx[b], idx[c] given) that triangle `id` meets: the
// sweep narrows the row to the cells its plane can reach, the filter decides each cell, and the undecided ones are
// taken (sat) or asked of CGAL (exact).
void triangleRow(const WindowContext& ctx, size_t id, const TriangleFilter& filter, const PlaneSweep& sweep,
                 const CellRange& range, int64_t idx[3], Local& local) {
  const int a = sweep.axis, b = (a + 1) % 3, c = (a + 2) % 3;
  const auto& bnd = ctx.boundary;
  int64_t from = range.first[a], to = range.last[a];
  if (sweep.usable) {
    const auto [lo, hi] = sweep.range(bnd[b][idx[b]], bnd[b][idx[b] + 1], bnd[c][idx[c]], bnd[c][idx[c] + 1]);
    const auto& table = bnd[a];
    const auto r = cellRangeOnAxis(
        int64_t(ctx.dims[a]), ctx.boundaryScale[a], [&](int64_t i) { return table[size_t(i)]; }, lo, hi);
    from = std::max(from, r[0]);
    to = std::min(to, r[1]);
  }
  double lo[3], hi[3], rel[2][3];
  for (int axis : {b, c}) {
    lo[axis] = bnd[axis][idx[axis]];
    hi[axis] = bnd[axis][idx[axis] + 1];
    rel[0][axis] = lo[axis] - filter.origin[axis];
    rel[1][axis] = hi[axis] - filter.origin[axis];
  }
  const bool sat = ctx.options.method == OverlapMethod::Sat;
  for (idx[a] = from; idx[a] <= to; ++idx[a]) {
    lo[a] = bnd[a][idx[a]];
    hi[a] = bnd[a][idx[a] + 1];
    rel[0][a] = lo[a] - filter.origin[a];
    rel[1][a] = hi[a] - filter.origin[a];
    const FilterResult r = filter.test(lo, hi, rel);
    bool hit = r == FilterResult::Overlap;
    if (r == FilterResult::Unknown) {
      ++local.fallbacks;
      hit = sat || triangleBoxExact(ctx.scene.triangles[id], Box{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}});
    }
    if (hit) ctx.emit(local, id, idx[0], idx[1], idx[2]);
  }
  local.tested += uint64_t(std::max<int64_t>(0, to - from + 1));
}

// A triangle's cells (sat or exact), row by row along the axis of its plane sweep.
void triangleCells(const WindowContext& ctx, size_t id, const Box& primBox, const CellRange& range,
                   const CellRange& fullRange, Local& local) {
  const Triangle& t = ctx.scene.triangles[id];
  const TriangleFilter filter = preparedFilter(ctx, t, fullRange);
  if (isDegenerate(t)) ++local.degenerate;
  const PlaneSweep sweep(filter, t, primBox);
  const int b = (sweep.axis + 1) % 3, c = (sweep.axis + 2) % 3;
  int64_t idx[3] = {0, 0, 0};
  for (idx[c] = range.first[c]; idx[c] <= range.last[c]; ++idx[c])
    for (idx[b] = range.first[b]; idx[b] <= range.last[b]; ++idx[b])
      triangleRow(ctx, id, filter, sweep, range, idx, local);
}

// The references of bounded primitive `id` in the window's cells, by the method of the options.
void voxelizePrimitive(const WindowContext& ctx, size_t id, Local& local) {
  const bool isTri = id < ctx.nTri;
  const Box primBox = isTri ? triangleBounds(ctx.scene.triangles[id]) : sphereBounds(ctx.scene.spheres[id - ctx.nTri]);
  const auto fullRange = rangeOf(ctx.grid, primBox);
  const auto range = clip(fullRange, ctx.window);
  if (!range) return;
  switch (ctx.options.method) {
    case OverlapMethod::BBox:
      forEachCell(ctx, *range, [&](int64_t i, int64_t j, int64_t k) { ctx.emit(local, id, i, j, k); });
      local.tested += range->count();
      return;
    case OverlapMethod::Center:
      centerCells(ctx, id, primBox, *range, local);
      local.tested += range->count();
      return;
    case OverlapMethod::Sat:
    case OverlapMethod::Exact:
      if (isTri) {
        triangleCells(ctx, id, primBox, *range, *fullRange, local);
      } else {
        sphereCells(ctx, id, *range, local);
        local.tested += range->count();
      }
  }
}

// Fails with LimitError when the window's estimated references would take more memory than the options allow.
// Returns the estimate of the window's references (estimateReferences) after checking it against the budget.
double checkReferenceBudget(const Scene& scene, const Grid& grid, const CellWindow& window, const PrimitiveList& ids,
                            const VoxelizeOptions& options) {
  const double estimate = estimateReferences(scene, grid, window, ids, options.progress);
  constexpr double kBytesPerReference = 44;  // packed entry, radix buffer, and the compressed cell lists
  if (estimate * kBytesPerReference > double(options.memoryLimitBytes))
    fail<LimitError>("grid ", grid.dims[0], "x", grid.dims[1], "x", grid.dims[2], " needs about ",
                     uint64_t(estimate * kBytesPerReference / (1 << 20)), " MiB for ", uint64_t(estimate),
                     " cell references, more than the ", options.memoryLimitBytes >> 20, " MiB allowed");
  return estimate;
}

// Voxelizes the primitives `ids` into the cells of `window` of the planned `grid`. A primitive's cell tests are the
// same whatever the window (the filter's error bounds come from its whole cell range), so a brick gets exactly the
// single grid's cells restricted to it, for every method.
void voxelizeWindow(const Scene& scene, Grid& grid, const CellWindow& window, const PrimitiveList& ids,
                    const VoxelizeOptions& options, VoxelizeStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const size_t nWork = ids.size();
  const double estimate = checkReferenceBudget(scene, grid, window, ids, options);
  WindowContext ctx(scene, grid, window, options);
  ctx.nWork = std::max<size_t>(nWork, 1);

  // Each thread's references reserved once, on huge pages, so that they are never copied to grow: its share of the
  // (generous) estimate, twice over when threads are few, since the primitives are not spread evenly. Address space
  // only until written.
  const double threads = double(std::max(1, tbb::this_task_arena::max_concurrency()));
  const size_t perThread = size_t(std::min(estimate, estimate * 2 / threads)) + 4096;
  tbb::enumerable_thread_specific<Local> locals([&] {
    Local l;
    if (ctx.packed) l.packedRefs.reserve(perThread);
    return l;
  });
  std::atomic<size_t>& done = ctx.done;
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nWork, 256), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled.load(std::memory_order_relaxed)) return;
    Local& local = locals.local();
    for (size_t n = r.begin(); n != r.end(); ++n) voxelizePrimitive(ctx, ids[n], local);
    const size_t finished = done.fetch_add(r.size()) + r.size();
    if (options.progress && !options.progress(0.9 * double(finished) / double(nWork))) cancelled = true;
  });
  if (cancelled) fail<Error>("voxelization cancelled");

  // The sort and gather report no fraction of their own; they ask again at 0.9 whether to go on.
  const auto check = [&] {
    if (options.progress && !options.progress(0.9)) fail<Error>("voxelization cancelled");
  };
  VoxelizeStats local = gatherReferences(locals, ctx.packed, ctx.primBits, ctx.keyBits, grid, check);
  if (options.progress && !options.progress(1.0)) fail<Error>("voxelization cancelled");
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = local;
}

}  // namespace

}  // namespace vox
