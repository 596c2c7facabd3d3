#include "vox/grid.h"

#include <algorithm>

#include "vox/error.h"

namespace vox {

std::string methodName(OverlapMethod method) {
  switch (method) {
    case OverlapMethod::Center: return "center";
    case OverlapMethod::BBox: return "bbox";
    case OverlapMethod::Sat: return "sat";
    case OverlapMethod::Exact: return "exact";
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

int64_t findCell(const Grid& grid, uint64_t key) {
  const auto it = std::lower_bound(grid.cellKeys.begin(), grid.cellKeys.end(), key);
  if (it == grid.cellKeys.end() || *it != key) return -1;
  return it - grid.cellKeys.begin();
}

// Cell c meets [lo, hi] iff b(c) <= hi and b(c+1) >= lo. The boundary formula is monotone in c (a product and a
// division of non-negative values, then an addition, are each monotone under round-to-nearest), so a division
// gives a first guess and a few steps against the true formula make it exact.
std::array<int64_t, 2> cellRange(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, double lo,
                                 double hi) {
  const int64_t n = dims[axis];
  const double l = bounds.lo[axis], h = bounds.hi[axis];
  if (!(hi >= l) || !(lo <= h)) return {1, 0};
  auto boundary = [&](int64_t c) { return cellBoundary(bounds, dims, axis, c); };
  const double scale = double(n) / (h - l);
  // first = smallest c in [0, n-1] with b(c+1) >= lo
  int64_t first = std::clamp<int64_t>(int64_t(std::floor((lo - l) * scale)), 0, n - 1);
  while (first > 0 && boundary(first) >= lo) --first;
  while (first < n - 1 && boundary(first + 1) < lo) ++first;
  // last = largest c in [0, n-1] with b(c) <= hi
  int64_t last = std::clamp<int64_t>(int64_t(std::floor((hi - l) * scale)), 0, n - 1);
  while (last < n - 1 && boundary(last + 1) <= hi) ++last;
  while (last > 0 && boundary(last) > hi) --last;
  return {first, last};
}

}  // namespace vox
