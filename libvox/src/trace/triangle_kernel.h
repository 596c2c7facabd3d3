// The ray-triangle arithmetic, written once as a template over the number type: `double` for the scalar test
// (intersect.cpp) and a GCC vector of doubles for the packet test over many rays (trace_packet.cpp). Both produce
// the very same t for the same ray and triangle: the library is compiled with -ffp-contract=off and without
// -ffast-math, so every operation below rounds the same way in a scalar or a vector register.
#pragma once

#include <type_traits>

namespace vox::kernel {

// Four rays at once (two SSE2 or one AVX2 register).
typedef double Double4 __attribute__((vector_size(32)));

// Cramer's rule on o + t d = v0 + u e1 + v e2 (the Moller-Trumbore system) with the normal n = e1 x e2 precomputed:
// with s = o - v0 and c = s x d, det = -d.n, u = e2.c / det, v = -e1.c / det, t = s.n / det. The closed barycentric
// test compares the numerators with det (sign-aware) instead of dividing first. Branch-free (bitwise & of the
// conditions, a select for the sign of det); a finite det is one with det - det == 0.
// Returns whether the ray meets the triangle at a t in [tMin, tMax] (a bool for double, a lane mask for Double4);
// `t` is written either way for Double4, and for double whenever the ray meets the closed triangle.
template <typename T>
[[gnu::always_inline]] inline auto triangleHit(const double* v0, const double* e1, const double* e2, const double* n,
                                               T ox, T oy, T oz, T dx, T dy, T dz, T tMin, T tMax, T& t) {
  const T det = -(dx * n[0] + dy * n[1] + dz * n[2]);
  const T sx = ox - v0[0], sy = oy - v0[1], sz = oz - v0[2];
  const T cx = sy * dz - sz * dy, cy = sz * dx - sx * dz, cz = sx * dy - sy * dx;
  const T uu = e2[0] * cx + e2[1] * cy + e2[2] * cz;
  const T vv = -(e1[0] * cx + e1[1] * cy + e1[2] * cz);
  const T sum = uu + vv;
  const auto positive = (uu >= 0) & (vv >= 0) & (sum <= det);
  const auto negative = (uu <= 0) & (vv <= 0) & (sum >= det);
  const auto inside = (det > 0) ? positive : negative;
  if constexpr (std::is_same_v<T, double>) {
    // One ray (intersectTriangle): most tests miss, and leaving here saves the division's latency. A ray that goes
    // on computes the very same t as the branch-free form, so hits are unchanged.
    if (!inside) return inside;
  }
  t = (sx * n[0] + sy * n[1] + sz * n[2]) / det;
  return (det != 0) & (det - det == 0) & inside & (t >= tMin) & (t <= tMax);
}

}  // namespace vox::kernel
