// Building the float copies of the cells' triangles and preparing a ray for the filter (float_filter.h explains the
// bound).
#include "trace/float_filter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace vox::filter {

namespace {

constexpr double kU = 0x1.0p-24;        // unit roundoff of float
constexpr double kUp = 1 + 0x1.0p-40;   // rounds a double bound up past the double rounding that computed it
constexpr double kToFloatUp = 1 + 0x1.0p-20;  // keeps a bound an upper bound through its rounding to float
constexpr int kMaxScaleExponent = 200;
constexpr double kMaxOrigin = 0x1.0p40;

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
      for (int a = 0; a < 3; ++a) m = std::max({m, std::fabs(t.v0[a] - fc.center[a]), std::fabs(t.e1[a]), std::fabs(t.e2[a])});
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

bool prepareFilterRay(const FloatCells& fc, const Ray& ray, FilterRay& out) {
  if (!fc.enabled) return false;
  const Vec3& d = ray.direction;
  const double dMax = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  if (!(dMax > 0) || !std::isfinite(dMax)) return false;
  // Direction scaled by a power of two to [1, 2) in its largest component: U, V, D, W all scale alike. The power is
  // read from the exponent bits (frexp and ldexp are library calls, per ray); subnormal or huge dMax skip the filter.
  const int biased = int((std::bit_cast<uint64_t>(dMax) >> 52) & 0x7ff);
  if (biased == 0 || biased >= 2046) return false;
  const double dScale = std::bit_cast<double>(uint64_t(2046 - biased) << 52);  // 2^(1023 - biased)
  double S[3], ad[3];
  for (int a = 0; a < 3; ++a) {
    const double o = (ray.origin[a] - fc.center[a]) * fc.scale;
    const double dd = d[a] * dScale;
    if (!(std::fabs(o) <= kMaxOrigin)) return false;
    out.o[a] = Float4{} + float(o);
    out.d[a] = Float4{} + float(dd);
    S[a] = std::fabs(o) * kUp + fc.vertexMax[a];
    ad[a] = std::fabs(dd);
  }
  const double C[3] = {S[1] * ad[2] + S[2] * ad[1], S[2] * ad[0] + S[0] * ad[2], S[0] * ad[1] + S[1] * ad[0]};
  const double um = fc.edgeMax[0] * C[0] + fc.edgeMax[1] * C[1] + fc.edgeMax[2] * C[2];
  const double dm = ad[0] * fc.normalMax[0] + ad[1] * fc.normalMax[1] + ad[2] * fc.normalMax[2];
  const double eta = 0x1.0p-120 * (1 + S[0] + S[1] + S[2] + C[0] + C[1] + C[2] + um + dm);
  const double eu = 12 * kU * um + eta;
  const double ed = 7 * kU * dm + eta;
  const double ew = ed + 2 * eu + 3 * kU * dm + 4 * kU * um;
  out.eu = Float4{} + float(eu * kToFloatUp);
  out.ew = Float4{} + float(ew * kToFloatUp);
  return true;
}

}  // namespace vox::filter
