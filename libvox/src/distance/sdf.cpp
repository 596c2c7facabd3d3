#include "vox/distance/sdf.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <span>
#include <utility>

#include "vox/core/error.h"
#include "vox/core/exact_number.h"
#include "vox/distance/centre_signs.h"
#include "distance/band_scan.h"
#include "vox/voxelize/fill.h"

namespace vox {

void checkSdfHalfWidth(double halfWidth, const char* what) {
  if (!(halfWidth > 0) || !(halfWidth <= kMaxSdfHalfWidth))
    fail<UsageError>(what, ": half-width ", exactNumber(halfWidth), " must be a number in (0, ",
                     exactNumber(kMaxSdfHalfWidth), "] cell widths");
}

namespace {

struct Candidate {
  uint64_t key;
  double d2;  // squared distance from the cell's centre to its nearest primitive
  bool operator<(const Candidate& o) const { return key < o.key; }
};

double smallestCellEdge(const Grid& grid) {
  double h = INFINITY;
  for (int a = 0; a < 3; ++a) h = std::min(h, (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a]);
  return h;
}

// Cells are processed in tiles of kTile^3 (band_scan.h): each primitive is binned into the tiles its box grown by
// the band's reach meets, and each tile keeps the nearest squared distance of its cells in a small dense array.
// Memory is then the band's cells and the bins, not one entry per (cell, primitive) pair (which took 0.5 GB for the
// bunny at 256^3).
using band::kTile;

struct TilePrim {
  uint64_t tile;
  uint32_t prim;
  bool operator<(const TilePrim& o) const { return tile != o.tile ? tile < o.tile : prim < o.prim; }
};

// The band's cells with their nearest squared distance, in pieces whose concatenation is in key order.
std::vector<std::vector<Candidate>> bandCandidates(const Grid& grid, const Scene& scene, double reach,
                                                   const SdfOptions& options, band::Route route) {
  const band::Primitives primitives(grid, scene, reach);
  const size_t prims = primitives.count();
  std::array<uint64_t, 3> tiles;
  for (int a = 0; a < 3; ++a) tiles[a] = (grid.dims[a] + kTile - 1) / kTile;
  // Bins, counted first and then written in place: per-thread vectors grown by push_back and then concatenated
  // held them twice over at the peak, with their growth's slack (docs/distance.md "Not met").
  const size_t chunk = 4096, chunks = (prims + chunk - 1) / chunk;
  const auto forTiles = [&](size_t p, const auto& visit) {
    const band::Reachable c = primitives.reach(p);
    if (c.empty()) return;
    for (int64_t tz = c.cells[2][0] / kTile; tz <= c.cells[2][1] / kTile; ++tz)
      for (int64_t ty = c.cells[1][0] / kTile; ty <= c.cells[1][1] / kTile; ++ty)
        for (int64_t tx = c.cells[0][0] / kTile; tx <= c.cells[0][1] / kTile; ++tx)
          visit(uint64_t(tx) + tiles[0] * (uint64_t(ty) + tiles[1] * uint64_t(tz)));
  };
  std::vector<size_t> chunkStarts(chunks + 1, 0);  // each chunk's first bin, after the prefix sum
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    size_t n = 0;
    for (size_t p = k * chunk; p < std::min(prims, (k + 1) * chunk); ++p) forTiles(p, [&](uint64_t) { ++n; });
    chunkStarts[k + 1] = n;
  });
  for (size_t k = 0; k < chunks; ++k) chunkStarts[k + 1] += chunkStarts[k];
  if (chunkStarts[chunks] * sizeof(TilePrim) > options.memoryLimitBytes)
    fail<LimitError>("signed distance band: ", chunkStarts[chunks], " primitive bins exceed the memory limit of ",
                     options.memoryLimitBytes >> 20, " MiB; use a narrower band or fewer cells");
  std::vector<TilePrim> bins(chunkStarts[chunks]);
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    TilePrim* out = bins.data() + chunkStarts[k];
    for (size_t p = k * chunk; p < std::min(prims, (k + 1) * chunk); ++p)
      forTiles(p, [&](uint64_t tile) { *out++ = {tile, uint32_t(p)}; });
  });
  tbb::parallel_sort(bins.begin(), bins.end());
  std::vector<size_t> starts;  // each tile's first bin
  for (size_t b = 0; b < bins.size(); ++b)
    if (b == 0 || bins[b].tile != bins[b - 1].tile) starts.push_back(b);
  starts.push_back(bins.size());
  // Tiles, a slab of whole z planes of tiles at a time: a slab's cells, sorted, are a contiguous stretch of the
  // band in key order, so the band is their concatenation and no array of all of them is ever sorted or copied.
  std::vector<std::array<size_t, 2>> slabs;  // [first, end) of `starts` indices
  for (size_t g = 0; g + 1 < starts.size(); ++g) {
    const uint64_t slab = bins[starts[g]].tile / (tiles[0] * tiles[1]);
    if (slabs.empty() || bins[starts[slabs.back()[0]]].tile / (tiles[0] * tiles[1]) != slab)
      slabs.push_back({g, g + 1});
    else
      slabs.back()[1] = g + 1;
  }
  std::vector<std::vector<Candidate>> pieces(slabs.size());
  std::atomic<uint64_t> done{0}, emitted{0};
  std::atomic<bool> cancelled{false}, overBudget{false};
  const uint64_t maxCells = options.memoryLimitBytes / (2 * sizeof(Candidate));
  const double reach2 = reach * reach;
  const size_t tileCount = starts.size() - 1;
  tbb::enumerable_thread_specific<band::TileEvaluator> evaluators;
  tbb::parallel_for(size_t(0), slabs.size(), [&](size_t slab) {
    std::vector<Candidate>& out = pieces[slab];
    band::TileEvaluator& evaluator = evaluators.local();
    std::vector<double> nearest;
    std::vector<uint32_t> tilePrims;
    for (size_t g = slabs[slab][0]; g < slabs[slab][1]; ++g) {
      if (cancelled || overBudget) return;
      const size_t before = out.size();
      const uint64_t tile = bins[starts[g]].tile;
      const int64_t t0[3] = {int64_t(tile % tiles[0]) * kTile, int64_t(tile / tiles[0] % tiles[1]) * kTile,
                             int64_t(tile / (tiles[0] * tiles[1])) * kTile};
      tilePrims.clear();
      for (size_t b = starts[g]; b < starts[g + 1]; ++b) tilePrims.push_back(bins[b].prim);
      evaluator.evaluate(primitives, route, t0, tilePrims.data(), tilePrims.size(), nearest);
      // Only the tile's cells inside the grid: an edge tile's others keep +infinity, which a reach that
      // overflowed to +infinity would once have let through as keys past the grid (issue 45).
      const int64_t end[3] = {std::min<int64_t>(kTile, int64_t(grid.dims[0]) - t0[0]),
                              std::min<int64_t>(kTile, int64_t(grid.dims[1]) - t0[1]),
                              std::min<int64_t>(kTile, int64_t(grid.dims[2]) - t0[2])};
      for (int64_t k = 0; k < end[2]; ++k)
        for (int64_t j = 0; j < end[1]; ++j)
          for (int64_t i = 0; i < end[0]; ++i) {
            const double d2 = nearest[size_t(i + kTile * (j + kTile * k))];
            if (d2 <= reach2) out.push_back({cellKey(grid.dims, t0[0] + i, t0[1] + j, t0[2] + k), d2});
          }
      if ((emitted += out.size() - before) > maxCells) overBudget = true;
      const uint64_t finished = ++done;
      if (options.progress && !options.progress(0.8 * double(finished) / double(tileCount))) cancelled = true;
    }
    std::sort(out.begin(), out.end());  // tiles are disjoint: each key comes once
  });
  if (cancelled) fail<Error>("signed distances cancelled");
  if (overBudget)
    fail<LimitError>("signed distance band: more than ", maxCells, " cells within ", exactNumber(options.halfWidth),
                     " cell widths, over the memory limit of ", options.memoryLimitBytes >> 20,
                     " MiB; use a narrower band or fewer cells");
  return pieces;
}

}  // namespace

SdfBand signedDistanceBand(const Grid& grid, const Scene& scene, const SdfOptions& options) {
  return band::signedDistanceBand(grid, scene, options, band::Route::kScan);
}

SdfBand band::signedDistanceBand(const Grid& grid, const Scene& scene, const SdfOptions& options, Route route) {
  checkSdfHalfWidth(options.halfWidth, "--sdf");
  const double reach = options.halfWidth * smallestCellEdge(grid);
  // Squared distances are compared with reach^2: an overflow would take every cell (storeSignedDistances works in
  // a frame where it cannot).
  if (!std::isfinite(reach * reach))
    fail<InputError>("--sdf: the band's reach ", reach, " squared overflows; scale the scene nearer 1");
  std::vector<std::vector<Candidate>> pieces = bandCandidates(grid, scene, reach, options, route);
  size_t total = 0;
  for (const auto& piece : pieces) total += piece.size();
  SdfBand band;
  band.keys.reserve(total);
  band.values.reserve(total);
  for (auto& piece : pieces) {  // each piece freed once copied: the band and its pieces are never both whole
    for (const Candidate& c : piece) band.keys.push_back(c.key), band.values.push_back(c.d2);
    std::vector<Candidate>().swap(piece);
  }
  // Signs: InsideTest at every band cell's centre, as libvox.sdf and Grid.distance ask it.
  std::function<bool(double)> signProgress;
  if (options.progress) signProgress = [&](double f) { return options.progress(0.8 + 0.15 * f); };
  const InsideTest test(scene);
  const std::vector<uint8_t> inside = centresInside(grid, test, band.keys, signProgress);
  std::atomic<uint64_t> done{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, band.keys.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled) return;
    for (size_t b = r.begin(); b < r.end(); ++b) {
      const double d = std::sqrt(band.values[b]);
      band.values[b] = d > 0 && inside[b] ? -d : d;  // a centre on the surface: +0
    }
    const uint64_t finished = done += r.size();
    if (options.progress && !options.progress(0.95 + 0.05 * double(finished) / double(band.keys.size())))
      cancelled = true;
  });
  if (cancelled) fail<Error>("signed distances cancelled");
  return band;
}

VoxelizeOptions withCubicCells(const Scene& scene, VoxelizeOptions options) {
  if (!options.resolution || options.bounds || options.dims) return options;
  const Grid plan = planGrid(scene, options);
  double cell = 0;
  for (int a = 0; a < 3; ++a) cell = std::max(cell, (plan.bounds.hi[a] - plan.bounds.lo[a]) / *options.resolution);
  Box cubic;
  for (int a = 0; a < 3; ++a) {
    const double extent = plan.bounds.hi[a] - plan.bounds.lo[a];
    const double n = std::max(1.0, std::ceil(extent / cell - 1e-9));
    const double centre = 0.5 * (plan.bounds.lo[a] + plan.bounds.hi[a]);
    cubic.lo.at(a) = centre - 0.5 * n * cell;
    cubic.hi.at(a) = cubic.lo[a] + n * cell;
  }
  options.bounds = cubic;
  return options;
}

void checkNumericDomainOfPlan(const Scene& scene, const VoxelizeOptions& options, bool signedDistances,
                              bool fractions) {
  if (!signedDistances && !fractions) return;
  const Grid plan = planGrid(scene, options);
  if (signedDistances) checkNumericDomain(scene, plan.bounds, plan.dims, sceneFrame(scene), true, "--sdf");
  if (fractions)
    checkNumericDomain(scene, plan.bounds, plan.dims, fractionFrame(scene, plan.bounds), false, "volume fractions");
}

namespace {

void storeFramedSignedDistances(Grid& grid, const Scene& scene, const SdfOptions& options);

// storeFramedSignedDistances over `framed`, the scene in `frame`, with the grid's bounds in the frame meanwhile; the
// distances then scaled back to the world's units.
void storeThroughFrame(Grid& grid, const Scene& framed, const PowerOfTwoFrame& frame, const SdfOptions& options) {
  {
    const FramedBounds framedBounds(grid, frame);
    storeFramedSignedDistances(grid, framed, options);
  }
  for (double& v : grid.sdfValues) v = frame.toWorld(v);
}

// Whether every coordinate comes back from the frame as it was: scaling by 2^-e rounds only a result below the
// smallest normal double, which a scene scaled up (e <= 0: its magnitude brought up to [1, 2)) never reaches.
bool roundTripsExactly(std::span<const Triangle> triangles, const PowerOfTwoFrame& frame) {
  if (frame.exponent <= 0) return true;
  for (const Triangle& t : triangles)
    for (const Vec3& v : t.v)
      for (int a = 0; a < 3; ++a)
        if (frame.toWorld(frame.toFrame(v[a])) != v[a]) return false;
  return true;
}

void scaleTriangles(HugeVector<Triangle>& triangles, double (PowerOfTwoFrame::*to)(double) const,
                    const PowerOfTwoFrame& frame) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); ++t)
      for (Vec3& v : triangles[t].v) v = {(frame.*to)(v.x), (frame.*to)(v.y), (frame.*to)(v.z)};
  });
}

// The scene in a frame whose triangles are the owner's own, moved and scaled in place, and given back scaled back
// when it ends (sceneInFrame for the rest: spheres and planes are few).
class SceneLentToFrame {
 public:
  SceneLentToFrame(Scene& owner, const PowerOfTwoFrame& frame) : owner_(owner), frame_(frame) {
    HugeVector<Triangle> triangles = std::move(owner.triangles);
    owner.triangles.clear();  // moved from: empty, so that sceneInFrame copies none
    try {
      framed_ = sceneInFrame(owner, frame);
    } catch (...) {
      owner.triangles = std::move(triangles);
      throw;
    }
    framed_.triangles = std::move(triangles);
    scaleTriangles(framed_.triangles, &PowerOfTwoFrame::toFrame, frame_);
  }
  ~SceneLentToFrame() {
    scaleTriangles(framed_.triangles, &PowerOfTwoFrame::toWorld, frame_);
    owner_.triangles = std::move(framed_.triangles);
  }
  SceneLentToFrame(const SceneLentToFrame&) = delete;
  SceneLentToFrame& operator=(const SceneLentToFrame&) = delete;
  const Scene& scene() const { return framed_; }

 private:
  Scene& owner_;
  PowerOfTwoFrame frame_;
  Scene framed_;
};

// The scene's power-of-two frame, after the checks of the half-width and of the numeric domain both routes make.
PowerOfTwoFrame checkedSdfFrame(const Grid& grid, const Scene& scene, const SdfOptions& options) {
  checkSdfHalfWidth(options.halfWidth, "--sdf");
  const PowerOfTwoFrame frame = sceneFrame(scene);
  checkNumericDomain(scene, grid.bounds, grid.dims, frame, true, "--sdf");
  return frame;
}

}  // namespace

// The band is computed in the scene's power-of-two frame (docs/limits.md "Numeric domain"): a scene's band at scale
// 2^k is its band at scale 1 times 2^k, bit for bit, and no squared distance overflows or underflows.
void storeSignedDistances(Grid& grid, const Scene& scene, const SdfOptions& options, bool /*filled*/) {
  const PowerOfTwoFrame frame = checkedSdfFrame(grid, scene, options);
  if (frame.identity()) return storeFramedSignedDistances(grid, scene, options);
  storeThroughFrame(grid, sceneInFrame(scene, frame), frame, options);
}

void storeSignedDistancesInPlace(Grid& grid, Scene& scene, const SdfOptions& options) {
  const PowerOfTwoFrame frame = checkedSdfFrame(grid, scene, options);
  if (frame.identity()) return storeFramedSignedDistances(grid, scene, options);
  if (!roundTripsExactly(scene.triangles, frame))
    return storeThroughFrame(grid, sceneInFrame(scene, frame), frame, options);
  const SceneLentToFrame lent(scene, frame);
  storeThroughFrame(grid, lent.scene(), frame, options);
}

namespace {

void storeFramedSignedDistances(Grid& grid, const Scene& scene, const SdfOptions& options) {
  // The signs come from InsideTest, not from the fill: nothing to fill on the side.
  SdfBand band = signedDistanceBand(grid, scene, options);
  grid.sdfHalfWidth = options.halfWidth;
  grid.sdfKeys = std::move(band.keys);
  grid.sdfValues = std::move(band.values);
}

}  // namespace

}  // namespace vox
