// A single-precision filter in front of the double ray-triangle test (triangle_kernel.h), four triangles at a time
// (issue 12). It evaluates the kernel's own expressions, in the same order, on float copies of the ray and of a
// cell's triangles (Accel::floatCells): with s = o - v0, c = s x d,
//   U = e2.c, V = -(e1.c), D = -(d.n), W = D - U - V.
// The double test hits only when U, V and W all have the sign of D (or are zero; W >= 0 is its sum <= det). The
// filter rejects a triangle only when one of the float U, V, W exceeds its error bound and another lies below minus
// its bound: then the exact values have opposite strict signs, and so do the double ones, which lie far closer to
// them than the float bound. Every other triangle goes to the double test, so the hit is the double test's hit.
//
// The error bounds (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., ch. 3: each operation rounds
// with relative error u = 2^-24, a sum of three products with gamma_3 = 3u / (1 - 3u)), per ray from bounds on the
// magnitudes: S_a >= |o'_a| + |v0'_a| (coordinates scaled about the grid's centre), C_x = S_y |d_z| + S_z |d_y| (and
// cyclically) >= |c_x|, Um = sum_a edgeMax_a C_a >= |U|, |V|, Dm = sum_a |d_a| normalMax_a >= |D|:
//   s:  2u S (two conversions, one subtraction)      c: 5u C (two conversions, a product, a subtraction)
//   U:  9.01u Um (the conversion of e2, the products, gamma_3)    D: 6.01u Dm    W: those plus 2u Dm + 3u Um
// We use 12u Um, 7u Dm and Ew = Ed + 2 Eu + 3u Dm + 4u Um: the extra (about 3u Um) covers the double test's own
// rounding (53-bit, under 10 * 2^-53 Um), and an absolute 2^-120 (1 + sum S + sum C + Um + Dm) the subnormal
// results of tiny components, whose error is absolute (2^-150 each) rather than relative. The scaling (a power of two
// chosen at build so that |v0'| <= 1; the direction by a power of two bringing its largest component to [1, 2))
// commutes with double rounding and changes none of the signs; a scene whose scale is beyond 2^+-200, or a ray
// origin beyond 2^40 of the scaled grid, does not use the filter.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "vox/trace/accel.h"
#include "vox/trace/ray.h"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace vox::filter {

typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

// One ray in float, every lane the same, with its error bounds.
struct FilterRay {
  Float4 o[3], d[3];
  Float4 eu, ew;  // bounds on |U - U*| (and V) and |W - W*|, see above
};

inline constexpr double kU = 0x1.0p-24;       // unit roundoff of float
inline constexpr double kUp = 1 + 0x1.0p-40;  // rounds a double bound up past the double rounding that computed it
inline constexpr double kToFloatUp = 1 + 0x1.0p-20;  // keeps a bound an upper bound through its rounding to float
inline constexpr double kMaxOrigin = 0x1.0p40;

// Prepares `ray` for the filter; false when the accel has no float cells or the ray is outside what the bound
// covers (then the walk tests every triangle in double). Inline, so that each compiled copy of the walk
// (traverse.cpp) has its own.
inline bool prepareFilterRay(const FloatCells& fc, const Ray& ray, FilterRay& out) {
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

// Bit l set for every lane l < count of `g` that the double test might hit (the others it certainly misses).
[[gnu::always_inline]] inline uint32_t maybeHits(const TriangleGroup4& g, const FilterRay& r, uint32_t count) {
  const auto row = [&g](int k) {
    Float4 v;
    __builtin_memcpy(&v, g.lane[k], sizeof(v));
    return v;
  };
  const Float4 sx = r.o[0] - row(0), sy = r.o[1] - row(1), sz = r.o[2] - row(2);
  const Float4 dx = r.d[0], dy = r.d[1], dz = r.d[2];
  const Float4 cx = sy * dz - sz * dy, cy = sz * dx - sx * dz, cz = sx * dy - sy * dx;
  const Float4 uu = row(6) * cx + row(7) * cy + row(8) * cz;
  const Float4 vv = -(row(3) * cx + row(4) * cy + row(5) * cz);
  const Float4 det = -(dx * row(9) + dy * row(10) + dz * row(11));
  const Float4 ww = (det - uu) - vv;
  const Int4 pos = (uu > r.eu) | (vv > r.eu) | (ww > r.ew);
  const Int4 neg = (uu < -r.eu) | (vv < -r.eu) | (ww < -r.ew);
  const Int4 miss = pos & neg;
  uint32_t bits;
#if defined(__SSE__)
  bits = uint32_t(_mm_movemask_ps(reinterpret_cast<__m128>(miss)));
#else
  bits = uint32_t(miss[0] & 1) | uint32_t(miss[1] & 2) | uint32_t(miss[2] & 4) | uint32_t(miss[3] & 8);
#endif
  return ~bits & ((1u << count) - 1);
}

// Fills accel.floatCells from accel.triangles and the grid's cell lists; leaves it disabled when the copies would
// exceed `maxBytes` or the scene's values are outside what the bound covers.
void buildFloatCells(Accel& accel, const Grid& grid, uint64_t maxBytes);

}  // namespace vox::filter
