// Triangle-box clipping (clip_triangle.h).
#include "core/clip_triangle.h"

#include <algorithm>

namespace vox {

namespace {

// Keeps the part of `in` where sign * (p[axis] - bound) <= 0.
ClipPolygon clipPlane(const ClipPolygon& in, int axis, double bound, double sign) {
  ClipPolygon out;
  for (size_t i = 0; i < in.size; ++i) {
    const ClipVertex& a = in.v[i];
    const ClipVertex& b = in.v[(i + 1) % in.size];
    const double da = sign * (a.p[axis] - bound), db = sign * (b.p[axis] - bound);
    if (da <= 0 && out.size < out.v.size()) out.v[out.size++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double t = da / (da - db);
      ClipVertex c{a.p + (b.p - a.p) * t, a.bary + (b.bary - a.bary) * t};
      c.p.at(axis) = bound;  // exactly on the plane, whatever the rounding of
                             // the interpolation
      if (out.size < out.v.size()) out.v[out.size++] = c;
    }
  }
  return out;
}

}  // namespace

ClipPolygon clipTriangleToBox(const std::array<Vec3, 3>& t, const Box& box) {
  ClipPolygon poly;
  poly.v[0] = {t[0], {1, 0, 0}};
  poly.v[1] = {t[1], {0, 1, 0}};
  poly.v[2] = {t[2], {0, 0, 1}};
  poly.size = 3;
  for (int axis = 0; axis < 3 && poly.size > 0; ++axis) {
    poly = clipPlane(poly, axis, box.lo[axis], -1);
    if (poly.size > 0) poly = clipPlane(poly, axis, box.hi[axis], 1);
  }
  return poly;
}

Vec3 nearestBarycentric(const std::array<Vec3, 3>& t, const Vec3& p) {
  const Vec3 &a = t[0], &b = t[1], &c = t[2];
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 - d3 != 0 ? d1 / (d1 - d3) : 0;
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 - d6 != 0 ? d2 / (d2 - d6) : 0;
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) + (d5 - d6) != 0 ? (d4 - d3) / ((d4 - d3) + (d5 - d6)) : 0;
    return {0, 1 - w, w};
  }
  const double sum = va + vb + vc;
  if (!(sum != 0) || !std::isfinite(sum)) return {1, 0, 0};  // degenerate: every region test was inconclusive
  const double v = vb / sum, w = vc / sum;
  return {1 - v - w, v, w};
}

}  // namespace vox
