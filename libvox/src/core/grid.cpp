#include "vox/core/grid.h"

#include <algorithm>
#include <cmath>

#include "vox/core/cell_range.h"
#include "vox/core/error.h"
#include "vox/core/exact_number.h"

namespace vox {

std::string methodName(OverlapMethod method) {
  switch (method) {
    case OverlapMethod::Center:
      return "center";
    case OverlapMethod::BBox:
      return "bbox";
    case OverlapMethod::Sat:
      return "sat";
    case OverlapMethod::Exact:
      return "exact";
  }
  return "unknown";
}

OverlapMethod parseMethod(const std::string& name) {
  for (auto m : {OverlapMethod::Center, OverlapMethod::BBox, OverlapMethod::Sat, OverlapMethod::Exact})
    if (methodName(m) == name) return m;
  fail<InputError>("unknown overlap method '", name, "' (expected exact, sat, bbox or center)");
}

Box cellBox(const Grid& grid, uint32_t i, uint32_t j, uint32_t k) {
  const uint32_t idx[3] = {i, j, k};
  Box box;
  for (int a = 0; a < 3; ++a) {
    box.lo.at(a) = cellBoundary(grid.bounds, grid.dims, a, idx[a]);
    box.hi.at(a) = cellBoundary(grid.bounds, grid.dims, a, int64_t(idx[a]) + 1);
  }
  return box;
}

Vec3 cellCentre(const Grid& grid, uint64_t key) {
  const auto ijk = cellIndex(grid.dims, key);
  Vec3 c;
  for (int a = 0; a < 3; ++a) c.at(a) = cellCentreOnAxis(grid.bounds, grid.dims, a, ijk[a]);
  return c;
}

std::array<std::vector<double>, 3> cellCentresByAxis(const Grid& grid) {
  std::array<std::vector<double>, 3> centres;
  for (int a = 0; a < 3; ++a) {
    centres[a].resize(grid.dims[a]);
    for (uint32_t i = 0; i < grid.dims[a]; ++i) centres[a][i] = cellCentreOnAxis(grid.bounds, grid.dims, a, i);
  }
  return centres;
}

int64_t findCell(const Grid& grid, uint64_t key) {
  const auto it = std::lower_bound(grid.cellKeys.begin(), grid.cellKeys.end(), key);
  if (it == grid.cellKeys.end() || *it != key) return -1;
  return it - grid.cellKeys.begin();
}

bool isSolid(const Grid& grid, uint64_t key) {
  // The first run starting after `key`; the run before it is the only one that can hold it.
  const auto it = std::upper_bound(grid.solidRuns.begin(), grid.solidRuns.end(), key,
                                   [](uint64_t k, const CellRun& r) { return k < r.first; });
  if (it == grid.solidRuns.begin()) return false;
  const CellRun& r = *(it - 1);
  return key - r.first < r.count;
}

void appendSolidKey(std::vector<CellRun>& runs, uint64_t key) {
  if (!runs.empty() && runs.back().first + runs.back().count == key)
    ++runs.back().count;
  else
    runs.push_back({key, 1});
}

void checkSolidRuns(const std::vector<CellRun>& runs, uint64_t cellCount, const std::string& what) {
  uint64_t end = 0;  // one past the previous run
  for (size_t r = 0; r < runs.size(); ++r) {
    const CellRun& run = runs[r];
    if (run.count == 0) fail<InputError>(what, ": solid run ", r, " is empty");
    if (run.first >= cellCount || run.count > cellCount - run.first)
      fail<InputError>(what, ": solid run ", r, " reaches outside the grid");
    if (r > 0 && run.first <= end) fail<InputError>(what, ": solid run ", r, " not sorted, overlapping or adjacent");
    end = run.first + run.count;
  }
}

void checkSolidRunsMissCells(std::span<const uint64_t> sortedKeys, const std::vector<CellRun>& runs,
                             const std::string& what) {
  size_t c = 0;
  for (size_t r = 0; r < runs.size() && c < sortedKeys.size(); ++r) {
    while (c < sortedKeys.size() && sortedKeys[c] < runs[r].first) ++c;
    if (c < sortedKeys.size() && sortedKeys[c] - runs[r].first < runs[r].count)
      fail<InputError>(what, ": solid run ", r, " covers the occupied cell ", sortedKeys[c],
                       " (a cell is occupied or solid, not both)");
  }
}

namespace {

// Keys strictly ascending and inside a grid of `cells` cells, or the index of the first that is not.
size_t firstBadKey(std::span<const uint64_t> keys, uint64_t cells) {
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i] >= cells || (i > 0 && keys[i] <= keys[i - 1])) return i;
  return keys.size();
}

}  // namespace

void checkGridBeforeWrite(const Grid& grid, const std::string& what) {
  const uint64_t cells = grid.cellCount();
  if (const size_t i = firstBadKey(grid.cellKeys, cells); i < grid.cellKeys.size())
    fail<Error>(what, ": occupied cell key ", grid.cellKeys[i], " is repeated, out of order or outside the ", cells,
                " cells; not written");
  if (grid.cellStart.size() != grid.cellKeys.size() + 1 || grid.cellStart.back() != grid.primIds.size())
    fail<Error>(what, ": the cell table's starts do not match its cells; not written");
  checkSolidRuns(grid.solidRuns, cells, what);
  // A band may be empty (bounds or a half-width that reach no cell centre within HALF): the file says so.
  if (grid.sdfKeys.size() != grid.sdfValues.size() || (grid.sdfHalfWidth == 0 && !grid.sdfKeys.empty()))
    fail<Error>(what, ": the distance band has ", grid.sdfKeys.size(), " cells and ", grid.sdfValues.size(),
                " values at half-width ", exactNumber(grid.sdfHalfWidth), "; not written");
  if (grid.sdfHalfWidth != 0 && !(grid.sdfHalfWidth > 0 && grid.sdfHalfWidth <= 64))
    fail<Error>(what, ": distance band half-width ", exactNumber(grid.sdfHalfWidth),
                " is outside (0, 64]; not written");
  if (const size_t i = firstBadKey(grid.sdfKeys, cells); i < grid.sdfKeys.size())
    fail<Error>(what, ": distance band cell key ", grid.sdfKeys[i], " is repeated, out of order or outside the ", cells,
                " cells; not written");
  for (size_t i = 0; i < grid.sdfValues.size(); ++i)
    if (!std::isfinite(grid.sdfValues[i]))
      fail<Error>(what, ": signed distance ", grid.sdfValues[i], " at cell key ", grid.sdfKeys[i], "; not written");
  if (!grid.fractions.empty() && grid.fractions.size() != grid.cellKeys.size())
    fail<Error>(what, ": ", grid.fractions.size(), " volume fractions for ", grid.cellKeys.size(),
                " occupied cells; not written");
  for (size_t c = 0; c < grid.fractions.size(); ++c)
    if (!(grid.fractions[c] >= 0 && grid.fractions[c] <= 1))
      fail<Error>(what, ": volume fraction ", grid.fractions[c], " at cell key ", grid.cellKeys[c],
                  " is outside [0, 1]; not written");
}

std::array<int64_t, 2> cellRange(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, double lo,
                                 double hi) {
  const double scale = double(dims[axis]) / (bounds.hi[axis] - bounds.lo[axis]);
  return cellRangeOnAxis(
      dims[axis], scale, [&](int64_t c) { return cellBoundary(bounds, dims, axis, c); }, lo, hi);
}

}  // namespace vox
