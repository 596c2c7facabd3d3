#include "vox/trace/accel.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "trace/float_filter.h"
#include "vox/core/error.h"

namespace vox {

AccelKind parseAccel(const std::string& name) {
  if (name == "grid") return AccelKind::Grid;
  if (name == "none") return AccelKind::None;
  if (name == "uniform") return AccelKind::Uniform;
  fail<UsageError>("unknown acceleration '", name, "' (expected grid, uniform or none)");
}

uint32_t Accel::lookupSlow(uint32_t i, uint32_t j, uint32_t k) const {
  const uint64_t key = cellKey(grid->dims, i, j, k);
  const int64_t c = findCell(*grid, key);
  if (c >= 0) return uint32_t(c);
  if (isSolid(*grid, key)) return kSolidCell;
  return kEmptyCell;
}

CellBoundaries makeCellBoundaries(const Box& bounds, const std::array<uint32_t, 3>& dims) {
  CellBoundaries cb;
  cb.dims = dims;
  double minCell = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    cb.b[a].resize(size_t(dims[a]) + 1);
    for (int64_t i = 0; i <= int64_t(dims[a]); ++i) cb.b[a][size_t(i)] = cellBoundary(bounds, dims, a, i);
    const double lo = cb.b[a].front(), hi = cb.b[a].back();
    const double n = dims[a] == 0 ? 1.0 : double(dims[a]);
    cb.cellSize[a] = (hi - lo) / n;
    cb.cellsPerUnit[a] = hi > lo ? n / (hi - lo) : 0;
    cb.magnitude[a] = std::max(std::fabs(lo), std::fabs(hi));
    if (cb.cellSize[a] > 0) minCell = std::min(minCell, cb.cellSize[a]);
  }
  cb.minCell = std::isfinite(minCell) ? minCell : 0;
  return cb;
}

namespace {

// Tables cost 4 bytes per cell of every occupied block; beyond this the binary search is the better trade.
constexpr uint64_t kMaxTableBytes = uint64_t(1) << 30;
constexpr uint64_t kMaxBlocks = uint64_t(1) << 25;
constexpr uint64_t kMinBlockBudget = uint64_t(1) << 21;

void buildTables(Accel& accel, const Grid& grid) {
  const auto& dims = grid.dims;
  // Smallest block size (4 to 64 cells a side) whose block array stays small: under kMaxBlocks, and for a sparse
  // grid under a few dozen blocks per occupied cell or solid run (a crafted 303137x24624x1 grid of 6 occupied cells
  // took 29M blocks and 1.9 s to build at 4 cells a side; it gets 1.8M at 64).
  const uint64_t budget =
      std::min(kMaxBlocks, std::max(kMinBlockBudget, 64 * (uint64_t(grid.cellKeys.size()) + grid.solidRuns.size())));
  uint32_t shift = 0;
  for (uint32_t s = 2; s <= 6 && shift == 0; ++s) {
    uint64_t blocks = 1;
    for (int a = 0; a < 3; ++a) blocks *= (uint64_t(dims[a]) + (1u << s) - 1) >> s;
    if (blocks <= budget) shift = s;
  }
  if (shift == 0) return;
  std::array<uint32_t, 3> bd;
  for (int a = 0; a < 3; ++a) bd[a] = uint32_t((uint64_t(dims[a]) + (1u << shift) - 1) >> shift);
  const uint64_t blockCount = uint64_t(bd[0]) * bd[1] * bd[2];
  const auto blockOf = [&](const std::array<uint32_t, 3>& c) {
    return (c[0] >> shift) + bd[0] * ((c[1] >> shift) + uint64_t(bd[1]) * (c[2] >> shift));
  };
  // Count occupied blocks first, so that a scattered grid falls back before allocating.
  HugeVector<uint32_t> slot(blockCount, kEmptyCell);
  uint32_t used = 0;
  const uint64_t perBlock = uint64_t(1) << (3 * shift);
  const auto claim = [&](uint64_t key) {
    const uint64_t b = blockOf(cellIndex(dims, key));
    if (slot[b] == kEmptyCell) {
      if ((uint64_t(used) + 1) * perBlock * 4 > kMaxTableBytes) return false;
      slot[b] = used++;
    }
    return true;
  };
  for (uint64_t key : grid.cellKeys)
    if (!claim(key)) return;
  // A solid run visits each block it crosses once per row, not once per cell.
  for (const CellRun& run : grid.solidRuns)
    for (uint64_t key = run.first; key < run.first + run.count;) {
      if (!claim(key)) return;
      const uint64_t i = key % dims[0];
      const uint64_t blockEnd = std::min<uint64_t>(((i >> shift) + 1) << shift, dims[0]);
      key += std::min<uint64_t>(run.first + run.count - key, blockEnd - i);
    }
  accel.cellSlots.assign(uint64_t(used) * perBlock, kEmptyCell);
  const uint32_t m = (1u << shift) - 1;
  const auto entry = [&](const std::array<uint32_t, 3>& c) -> uint32_t& {
    return accel.cellSlots[(uint64_t(slot[blockOf(c)]) << (3 * shift)) +
                           ((c[0] & m) | ((c[1] & m) << shift) | ((c[2] & m) << (2 * shift)))];
  };
  for (const CellRun& run : grid.solidRuns)
    for (uint64_t key = run.first; key < run.first + run.count; ++key) entry(cellIndex(dims, key)) = kSolidCell;
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) entry(cellIndex(dims, grid.cellKeys[c])) = uint32_t(c);
  accel.blockShift = shift;
  accel.blockDims = bd;
  accel.blockSlot = std::move(slot);
}

}  // namespace

void buildEmptyShift(Accel& accel) {
  accel.emptyShift.clear();
  if (accel.blockShift == 0) return;
  // A pyramid of emptiness: level 0 the blocks (1 = empty), level L the aligned boxes of 2^L blocks a side, each
  // empty when its eight children are (those past the grid count as empty), up to the one box holding the grid. Every
  // level is an eighth of the one below, so the pyramid costs a seventh of the blocks more.
  std::vector<std::array<uint32_t, 3>> dims{accel.blockDims};
  std::vector<std::vector<uint8_t>> level(1);
  level[0].resize(accel.blockSlot.size());
  for (size_t b = 0; b < level[0].size(); ++b) level[0][b] = accel.blockSlot[b] == kEmptyCell;
  while (std::max({dims.back()[0], dims.back()[1], dims.back()[2]}) > 1) {
    const std::array<uint32_t, 3> d = dims.back(), h{(d[0] + 1) / 2, (d[1] + 1) / 2, (d[2] + 1) / 2};
    std::vector<uint8_t> up(size_t(h[0]) * h[1] * h[2], 1);
    const std::vector<uint8_t>& below = level.back();
    for (uint32_t z = 0; z < d[2]; ++z)
      for (uint32_t y = 0; y < d[1]; ++y)
        for (uint32_t x = 0; x < d[0]; ++x)
          if (!below[x + d[0] * (y + uint64_t(d[1]) * z)]) up[x / 2 + h[0] * (y / 2 + uint64_t(h[1]) * (z / 2))] = 0;
    level.push_back(std::move(up));
    dims.push_back(h);
  }
  // Top down, each entry becomes 1 + the level of the largest empty box holding it (0: not empty): its parent's
  // value when the parent is empty, else its own level.
  const size_t top = level.size() - 1;
  for (uint8_t& v : level[top]) v = v ? uint8_t(top + 1) : 0;
  for (size_t l = top; l-- > 0;) {
    const std::array<uint32_t, 3> d = dims[l], h = dims[l + 1];
    const std::vector<uint8_t>& parent = level[l + 1];
    std::vector<uint8_t>& v = level[l];
    for (uint32_t z = 0; z < d[2]; ++z)
      for (uint32_t y = 0; y < d[1]; ++y)
        for (uint32_t x = 0; x < d[0]; ++x) {
          uint8_t& e = v[x + d[0] * (y + uint64_t(d[1]) * z)];
          const uint8_t p = parent[x / 2 + h[0] * (y / 2 + uint64_t(h[1]) * (z / 2))];
          if (e) e = p != 0 ? p : uint8_t(l + 1);
        }
  }
  accel.emptyShift.assign(level[0].size(), 0);
  for (size_t b = 0; b < level[0].size(); ++b)
    if (level[0][b]) accel.emptyShift[b] = uint8_t(accel.blockShift + level[0][b] - 1);
}

Accel buildAccel(const Scene& scene, const Grid& grid, AccelKind requested) {
  // The uniform walk is the grid walk without cell boxes.
  const AccelKind kind = requested == AccelKind::Uniform ? AccelKind::Grid : requested;
  Accel accel;
  accel.kind = kind;
  accel.grid = &grid;
  accel.triangleCount = uint32_t(scene.triangles.size());
  accel.sphereCount = uint32_t(scene.spheres.size());
  accel.planeCount = uint32_t(scene.planes.size());
  const uint64_t primCount = scene.primitiveCount();
  if (primCount >= kEmptyCell) fail<LimitError>("scene has ", primCount, " primitives; at most 2^32 - 2 can be traced");
  accel.triangles.reserve(scene.triangles.size());
  for (const Triangle& t : scene.triangles) accel.triangles.push_back(prepareTriangle(t));
  accel.spheres.reserve(scene.spheres.size());
  for (const Sphere& s : scene.spheres) accel.spheres.push_back(prepareSphere(s));
  accel.planes = scene.planes;

  const uint32_t firstPlane = accel.triangleCount + accel.sphereCount;
  for (uint32_t id : grid.outsidePrims) {
    if (id >= firstPlane) fail<InputError>("grid: outside primitive id ", id, " is not a bounded primitive");
    accel.alwaysTested.push_back(id);
  }
  for (uint32_t p = 0; p < accel.planeCount; ++p) accel.alwaysTested.push_back(firstPlane + p);
  std::sort(accel.alwaysTested.begin(), accel.alwaysTested.end());
  accel.alwaysTested.erase(std::unique(accel.alwaysTested.begin(), accel.alwaysTested.end()), accel.alwaysTested.end());

  // The cell lookup is built for both kinds: the voxels and count modes walk the grid whatever the accel.
  for (uint32_t id : grid.primIds)
    if (id >= firstPlane) fail<InputError>("grid: cell primitive id ", id, " is not a bounded primitive");
  if (grid.occupiedCount() >= kSolidCell)
    fail<LimitError>("grid has ", grid.occupiedCount(), " occupied cells; at most 2^32 - 2 can be traced");
  buildTables(accel, grid);
  buildEmptyShift(accel);
  accel.boundaries = makeCellBoundaries(grid.bounds, grid.dims);
  if (kind == AccelKind::Grid && grid.primIds.size() <= kMaxCellTriangleBytes / sizeof(TriangleData)) {
    accel.cellTriangles.resize(grid.primIds.size());
    for (size_t r = 0; r < grid.primIds.size(); ++r)
      if (grid.primIds[r] < accel.triangleCount) accel.cellTriangles[r] = accel.triangles[grid.primIds[r]];
  }
  if (kind == AccelKind::Grid) filter::buildFloatCells(accel, grid, kMaxCellTriangleBytes);
  if (requested == AccelKind::Grid) buildCellBoxes(accel);
  return accel;
}

}  // namespace vox
