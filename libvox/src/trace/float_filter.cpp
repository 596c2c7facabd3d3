// Building the float copies of the cells' triangles and preparing a ray for the filter (float_filter.h explains the
// bound).
#include "trace/float_filter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace vox::filter {

namespace {

constexpr int kMaxScaleExponent = 200;

// The smallest power of two 2^e with m * 2^-e <= 1 (m > 0, finite): its exponent e.
int scaleExponent(double m) {
  int e = 0;
  std::frexp(m, &e);  // m = f 2^e, f in [0.5, 1)
  return e;
}

// The triangles of one cell (the ids of grid.primIds[begin, end) below triangleCount, a prefix) as groups.
void appendCell(FloatCells& fc, const Accel& accel, const Grid& grid, uint64_t begin, uint64_t end) {
  uint32_t count = 0;
  while (begin + count < end && grid.primIds[begin + count] < accel.triangleCount) ++count;
  fc.cells.push_back({uint32_t(fc.groups.size()), count});
  const double s = fc.scale, s2 = s * s;
  for (uint32_t k = 0; k < count; ++k) {
    if (k % 4 == 0) fc.groups.push_back(TriangleGroup4{});
    TriangleGroup4& g = fc.groups.back();
    const uint32_t id = grid.primIds[begin + k], l = k % 4;
    const TriangleData& t = accel.triangles[id];
    g.id[l] = id;
    for (int a = 0; a < 3; ++a) {
      const double v = (t.v0[a] - fc.center[a]) * s, e1 = t.e1[a] * s, e2 = t.e2[a] * s, n = t.n[a] * s2;
      g.lane[a][l] = float(v), g.lane[3 + a][l] = float(e1), g.lane[6 + a][l] = float(e2), g.lane[9 + a][l] = float(n);
      fc.vertexMax[a] = std::max(fc.vertexMax[a], std::fabs(v) * kUp);
      fc.edgeMax[a] = std::max({fc.edgeMax[a], std::fabs(e1), std::fabs(e2)});
      fc.normalMax[a] = std::max(fc.normalMax[a], std::fabs(n));
    }
  }
}

}  // namespace

void buildFloatCells(Accel& accel, const Grid& grid, uint64_t maxBytes) {
  FloatCells fc;
  const size_t cellCount = grid.cellKeys.size();
  // The scale: from the largest vertex distance to the grid's centre, over the triangles of the cells.
  fc.center = (grid.bounds.lo + grid.bounds.hi) * 0.5;
  double m = 0;
  uint64_t groupCount = 0;
  for (size_t c = 0; c < cellCount; ++c) {
    uint64_t n = 0;
    for (uint64_t r = grid.cellStart[c]; r < grid.cellStart[c + 1] && grid.primIds[r] < accel.triangleCount; ++r, ++n) {
      const TriangleData& t = accel.triangles[grid.primIds[r]];
      for (int a = 0; a < 3; ++a)
        m = std::max({m, std::fabs(t.v0[a] - fc.center[a]), std::fabs(t.e1[a]), std::fabs(t.e2[a])});
    }
    groupCount += (n + 3) / 4;
  }
  if (!std::isfinite(m) || !(m > 0) || !isFinite(fc.center)) return;
  if (groupCount * sizeof(TriangleGroup4) + (cellCount + 1 + accel.cellSlots.size()) * sizeof(FloatCells::Cell) >
          maxBytes ||
      groupCount >= std::numeric_limits<uint32_t>::max())
    return;
  const int e = scaleExponent(m);
  if (e < -kMaxScaleExponent || e > kMaxScaleExponent) return;
  fc.scale = std::ldexp(1.0, -e);
  fc.cells.reserve(cellCount + 1);
  fc.groups.reserve(groupCount);
  for (size_t c = 0; c < cellCount; ++c) appendCell(fc, accel, grid, grid.cellStart[c], grid.cellStart[c + 1]);
  fc.cells.push_back({uint32_t(fc.groups.size()), 0});
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(fc.normalMax[a]) || !std::isfinite(fc.vertexMax[a]) || !std::isfinite(fc.edgeMax[a])) return;
  if (accel.blockShift != 0) {
    fc.slots.resize(accel.cellSlots.size(), {0, 0});
    for (size_t k = 0; k < accel.cellSlots.size(); ++k)
      if (accel.cellSlots[k] < kSolidCell) fc.slots[k] = fc.cells[accel.cellSlots[k]];
  }
  fc.enabled = true;
  accel.floatCells = std::move(fc);
}

}  // namespace vox::filter
