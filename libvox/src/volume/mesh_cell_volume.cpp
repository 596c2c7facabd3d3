#include "volume/mesh_cell_volume.h"

#include <algorithm>
#include <array>

#include "vox/core/exact_orient.h"

namespace vox::volume {

namespace {

// An edge of a triangle that crosses the plane x = X + dx: `below` has x <= X, `above` has x > X.
struct CrossingEdge {
  const Vec3* below;
  const Vec3* above;
};

// The section of a triangle by x = X + dx runs from the point on edge `down` (which the triangle's boundary, in its
// vertex order, traverses from above to below) to the point on edge `up`: with that direction d, the section's
// outward normal in the (y, z) plane is (d_z, -d_y) for an outward-oriented triangle.
struct TriangleSection {
  CrossingEdge down;
  CrossingEdge up;
};

std::optional<TriangleSection> sectionAt(const Triangle& t, double X) {
  const bool below[3] = {t.v[0].x <= X, t.v[1].x <= X, t.v[2].x <= X};
  std::optional<CrossingEdge> down, up;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (below[i] && !below[j]) up = CrossingEdge{&t.v[i], &t.v[j]};
    if (!below[i] && below[j]) down = CrossingEdge{&t.v[j], &t.v[i]};
  }
  if (!down || !up) return std::nullopt;
  return TriangleSection{*down, *up};
}

// Whether the edge's point at x = X + dx lies above y = Y + dy. Exact: the sign of the orientation of the edge's
// projection and (X, Y), and where that is 0, the sign the perturbation gives (dx first, then dy).
bool aboveLine(const CrossingEdge& e, double X, double Y) {
  const int o = orient2d(e.below->x, e.below->y, e.above->x, e.above->y, X, Y);
  if (o != 0) return o < 0;
  return e.above->y > e.below->y;
}

// The edge's point at x = X, in the frame whose origin is (X, Y, Z). Every caller with the same X and Y gets the same
// y bit for bit, which keeps lineCrossing and sectionFlux on the same parameter where a section crosses y = Y.
struct SectionPoint {
  double y, z;
};
SectionPoint edgePoint(const CrossingEdge& e, double X, double Y, double Z) {
  const double bx = e.below->x - X, ax = e.above->x - X;
  const double den = ax - bx;
  const double s = den > 0 ? std::clamp(-bx / den, 0.0, 1.0) : 0.0;
  const double by = e.below->y - Y, ay = e.above->y - Y;
  const double bz = e.below->z - Z, az = e.above->z - Z;
  return {by + (ay - by) * s, bz + (az - bz) * s};
}

// Parameter along d -> u where the section meets y = lineY (frame units); the ends' sides were decided exactly, so
// rounding may only move it along the segment, never off it.
double crossParam(const SectionPoint& d, const SectionPoint& u, double lineY) {
  const double den = u.y - d.y;
  return den != 0 ? std::clamp((lineY - d.y) / den, 0.0, 1.0) : 0.5;
}

// The integral of (y - y0) dz along the part of the triangle's section at x = x1 + dx inside the face
// (y0, y1] x (z0, z1], directed as TriangleSection says: the face's share of the 2-D divergence theorem, without its
// edge term.
double sectionFlux(const Triangle& t, const CellPlanes& c) {
  const double X = c.hi[0], Y = c.hi[1], Z = c.lo[2];
  const std::optional<TriangleSection> s = sectionAt(t, X);
  if (!s) return 0;
  const bool dHi = aboveLine(s->down, X, Y), uHi = aboveLine(s->up, X, Y);
  const bool dLo = aboveLine(s->down, X, c.lo[1]), uLo = aboveLine(s->up, X, c.lo[1]);
  if ((dHi && uHi) || (!dLo && !uLo)) return 0;
  const SectionPoint d = edgePoint(s->down, X, Y, Z), u = edgePoint(s->up, X, Y, Z);
  const double dz = u.z - d.z;
  if (dz == 0) return 0;  // runs along z = const: no flux of (y - y0, 0)
  const double hy = c.hi[1] - c.lo[1], hz = c.hi[2] - c.lo[2], yLo = c.lo[1] - Y;
  double ta = 0, tb = 1;
  if (dHi != uHi) {
    const double th = crossParam(d, u, 0);
    (dHi ? ta : tb) = th;
  }
  if (dLo != uLo) {
    const double tl = crossParam(d, u, yLo);
    if (dLo)
      tb = std::min(tb, tl);
    else
      ta = std::max(ta, tl);
  }
  const double z0 = (0 - d.z) / dz, z1 = (hz - d.z) / dz;
  ta = std::max(ta, std::min(z0, z1));
  tb = std::min(tb, std::max(z0, z1));
  if (!(ta < tb)) return 0;
  const auto at = [&](double p) {
    return SectionPoint{std::clamp(d.y + (u.y - d.y) * p, yLo, 0.0), std::clamp(d.z + dz * p, 0.0, hz)};
  };
  const SectionPoint p = at(ta), q = at(tb);
  return (q.z - p.z) * (0.5 * (p.y + q.y) + hy);
}

// The flux of (x - x0, 0, 0) through the part of t inside the cell: the integral of (x - x0) n_x dA, i.e. the
// yz-projected signed area of each fan triangle times the mean x of its corners (x is affine on the plane).
double clippedFlux(const Triangle& t, const CellPlanes& c) {
  const bool xAligned = t.v[0].x == t.v[1].x && t.v[1].x == t.v[2].x;
  // A triangle in a plane x = const is inside the cell's x range (x0, x1] or not, decided on its exact coordinate:
  // on x = x1 its whole area counts, on x = x0 none (the perturbation moves the cell to x0 + dx).
  if (xAligned && !(t.v[0].x > c.lo[0] && t.v[0].x <= c.hi[0])) return 0;
  Polygon poly;
  poly.n = 3;
  for (int i = 0; i < 3; ++i) poly.v[i] = {t.v[i].x - c.lo[0], t.v[i].y - c.lo[1], t.v[i].z - c.lo[2]};
  for (int axis = xAligned ? 1 : 0; axis < 3 && poly.n > 2; ++axis) {
    poly = clipPolygon(poly, axis, 0, false);
    if (poly.n > 2) poly = clipPolygon(poly, axis, c.hi[axis] - c.lo[axis], true);
  }
  return polygonFlux(poly);
}

}  // namespace

std::optional<LineCrossing> lineCrossing(const Triangle& t, double X, double Y, double zOrigin) {
  const std::optional<TriangleSection> s = sectionAt(t, X);
  if (!s) return std::nullopt;
  const bool dAbove = aboveLine(s->down, X, Y), uAbove = aboveLine(s->up, X, Y);
  if (dAbove == uAbove) return std::nullopt;
  const SectionPoint d = edgePoint(s->down, X, Y, zOrigin), u = edgePoint(s->up, X, Y, zOrigin);
  const double th = crossParam(d, u, 0);
  // Going up the line we cross the section from d's side to u's; with the outward normal (d_z, -d_y) that enters
  // the solid when d lies below the line.
  return LineCrossing{d.z + (u.z - d.z) * th, dAbove ? -1 : 1};
}

double cellMeshVolume(std::span<const Triangle* const> triangles, const CellPlanes& cell, double edgeIntegral) {
  double flux = 0, face = 0;
  for (const Triangle* t : triangles) {
    flux += clippedFlux(*t, cell);
    face += sectionFlux(*t, cell);
  }
  const double hx = cell.hi[0] - cell.lo[0], hy = cell.hi[1] - cell.lo[1];
  return flux + hx * (face + hy * edgeIntegral);
}

Polygon clipPolygon(const Polygon& in, int axis, double value, bool keepBelow) {
  Polygon out;
  for (int i = 0; i < in.n; ++i) {
    const Vec3& p = in.v[i];
    const Vec3& q = in.v[(i + 1) % in.n];
    const bool pIn = keepBelow ? p[axis] <= value : p[axis] >= value;
    const bool qIn = keepBelow ? q[axis] <= value : q[axis] >= value;
    if (pIn) out.v[out.n++] = p;
    if (pIn != qIn) {
      const double t = (value - p[axis]) / (q[axis] - p[axis]);
      Vec3 r = p + (q - p) * t;
      r.at(axis) = value;
      out.v[out.n++] = r;
    }
  }
  return out;
}

double polygonFlux(const Polygon& poly) {
  double flux = 0;
  for (int i = 1; i + 1 < poly.n; ++i) {
    const Vec3 a = poly.v[i] - poly.v[0], b = poly.v[i + 1] - poly.v[0];
    flux += (a.y * b.z - a.z * b.y) * (poly.v[0].x + poly.v[i].x + poly.v[i + 1].x);
  }
  return flux / 6;
}

}  // namespace vox::volume
