#include "vox/core/grid.h"

#include <algorithm>

#include "vox/core/cell_range.h"
#include "vox/core/error.h"

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

std::array<int64_t, 2> cellRange(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, double lo,
                                 double hi) {
  const double scale = double(dims[axis]) / (bounds.hi[axis] - bounds.lo[axis]);
  return cellRangeOnAxis(
      dims[axis], scale, [&](int64_t c) { return cellBoundary(bounds, dims, axis, c); }, lo, hi);
}

}  // namespace vox
