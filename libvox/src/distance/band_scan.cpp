#include "distance/band_scan.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vox::band {

namespace {

// Constraints whose x coefficient is smaller than this bound no interval end (their quotient would lose the
// interval's accuracy); they only empty a row that no x in the reach box can satisfy.
constexpr double kMinSlope = 1e-3;

// rowLowerBounds' extra allowance per unit of |p - a|_1 (there).
constexpr double kReorderSlack = 1e-15;

// The row constraints of a triangle whose centres lie in `box` (the reach box's first and last centres).
//
// Why they hold: rowLowerBounds(p) <= reach^2 needs h <= reach (1 + 2^-52) and every edge's computed
// dot(m_e, p - v_e) - err <= the same, with err (its rounding included) <= errMax over the box. The computed dot
// products differ from the real n . (p - a) and m_e . (p - v_e) by at most 4 ulps of |p - v|_1 <= paMax, so every
// centre that can pass has n . (p - a) <= T, -n . (p - a) <= T and m_e . (p - a) <= T + m_e . (v_e - a), with
// T = (reach + errMax) (1 + 1e-12) + 1e-15 paMax. The rows evaluate these with a few more roundings, each a few
// ulps of T + paMax (the differences p - a are of doubles within paMax of each other), divided by a slope of at
// least kMinSlope (the quotient taken as a product with 1 / cx: two roundings more): the allowance of
// 1e-9 (T + paMax) added to every c0 covers them a thousand times over.
RowScan rowScan(const Triangle& t, const TriangleLowerBound& bound, const Box& box, double reach) {
  RowScan rows;
  if (!bound.usable) return rows;
  const Vec3& a = t.v[0];
  double paMax = 0, errSpan = 0;
  for (int axis = 0; axis < 3; ++axis) {
    double far = 0;
    for (const Vec3& v : t.v)
      far = std::max({far, std::fabs(box.lo[axis] - v[axis]), std::fabs(box.hi[axis] - v[axis])});
    paMax += far;
    errSpan += std::max(std::fabs(box.lo[axis] - a[axis]), std::fabs(box.hi[axis] - a[axis]));
  }
  const double errMax = ((bound.slack + kReorderSlack) * errSpan + bound.slackAt0) * (1 + 1e-10);
  const double T = (reach + errMax) * (1 + 1e-12) + 1e-15 * paMax;
  const double allowance = 1e-9 * (T + paMax);
  const Vec3& n = bound.normal;
  RowScan::Constraint all[5] = {{n.x, n.y, n.z, T + allowance, 0}, {-n.x, -n.y, -n.z, T + allowance, 0}};
  for (int e = 0; e < 3; ++e) {
    const Vec3& m = bound.edgeNormals[e];
    all[2 + e] = {m.x, m.y, m.z, T + dot(m, t.v[e] - a) + allowance, 0};
  }
  for (const RowScan::Constraint& c : all)
    if (c.cx >= kMinSlope) rows.constraints[size_t(rows.count++)] = c;
  rows.upper = rows.count;
  for (const RowScan::Constraint& c : all)
    if (c.cx <= -kMinSlope) rows.constraints[size_t(rows.count++)] = c;
  rows.lower = rows.count;
  for (const RowScan::Constraint& c : all)
    if (std::fabs(c.cx) < kMinSlope) rows.constraints[size_t(rows.count++)] = c;
  for (int e = 0; e < rows.lower; ++e) rows.constraints[size_t(e)].inverse = 1 / rows.constraints[size_t(e)].cx;
  rows.dxMax = std::max(std::fabs(box.lo.x - a.x), std::fabs(box.hi.x - a.x));
  return rows;
}

// Two doubles, SSE2's width (the baseline): every operation rounds as its scalar twin.
using Double2 = double __attribute__((vector_size(16)));

Double2 max2(Double2 a, Double2 b) { return a > b ? a : b; }
Double2 abs2(Double2 a) { return a < 0 ? -a : a; }

// squaredDistanceToTriangleWithin's lower bound (closest_point.cpp) at the centres (x[m], y, z), m in [0, n), into
// out[0, n) (x and out readable and writable one past n), with each dot product's y and z terms summed once for the
// row. That order moves a dot product's rounding by at most 2 ulps of the sum of its terms' magnitudes, at most
// 2.3e-16 |p - v|_1; the allowance err is raised by 1e-15 per unit of |p - a|_1 to cover it (the part from
// |v - a| is within slackAt0, 1e-13 of the triangle's size or more), so that the bound still never exceeds the
// computed distance.
void rowLowerBounds(const Triangle& t, const TriangleLowerBound& bound, const double* x, size_t n, double y, double z,
                    double* out) {
  if (!bound.usable) {
    std::fill(out, out + n, 0.0);
    return;
  }
  const Vec3& a = t.v[0];
  const Vec3& nn = bound.normal;
  const Vec3* m = bound.edgeNormals.data();
  const double ry = y - a.y, rz = z - a.z;
  const double slack = bound.slack + kReorderSlack;
  const double kErr = slack * (std::fabs(ry) + std::fabs(rz)) + bound.slackAt0;
  const double kN = nn.y * ry + nn.z * rz;
  const double k0 = m[0].y * ry + m[0].z * rz;
  const double k1 = m[1].y * (y - t.v[1].y) + m[1].z * (z - t.v[1].z);
  const double k2 = m[2].y * (y - t.v[2].y) + m[2].z * (z - t.v[2].z);
  for (size_t i = 0; i < n; i += 2) {
    Double2 px;
    __builtin_memcpy(&px, x + i, sizeof px);
    const Double2 p0 = px - a.x;
    const Double2 err = slack * abs2(p0) + kErr;
    const Double2 h = max2(Double2{0, 0}, abs2(nn.x * p0 + kN) - err);
    const Double2 o0 = m[0].x * p0 + k0, o1 = m[1].x * (px - t.v[1].x) + k1, o2 = m[2].x * (px - t.v[2].x) + k2;
    const Double2 s = max2(Double2{0, 0}, max2(max2(o0, o1), o2) - err);
    const Double2 lb = h * h + s * s;
    __builtin_memcpy(out + i, &lb, sizeof lb);
  }
}

size_t tileIndex(int64_t i, int64_t j, int64_t k) { return size_t(i) + kTile * (size_t(j) + kTile * size_t(k)); }

}  // namespace

Primitives::Primitives(const Grid& grid, const Scene& scene, double reachDistance)
    : grid(grid),
      scene(scene),
      centres(cellCentresByAxis(grid)),
      reachDistance(reachDistance),
      reach2(reachDistance * reachDistance) {
  for (const Sphere& s : scene.spheres) shapes.push_back(ellipsoidShape(s));
}

Reachable Primitives::reach(size_t p) const {
  const Box b = box(p);
  Reachable r;
  for (int a = 0; a < 3; ++a)
    r.cells[a] = cellRange(grid.bounds, grid.dims, a, b.lo[a] - reachDistance, b.hi[a] + reachDistance);
  return r;
}

RowScan Primitives::rows(size_t p, const TriangleLowerBound& bound, const Reachable& c) const {
  Box centreBox;
  for (int a = 0; a < 3; ++a) {
    centreBox.lo.at(a) = centres[a][size_t(c.cells[a][0])];
    centreBox.hi.at(a) = centres[a][size_t(c.cells[a][1])];
  }
  return rowScan(scene.triangles[p], bound, centreBox, reachDistance);
}

Box Primitives::box(size_t p) const {
  return p < scene.triangles.size() ? triangleBounds(scene.triangles[p])
                                    : ellipsoidBounds(shapes[p - scene.triangles.size()]);
}

namespace {

// The primitive's cells in the tile: its reach box cut to the tile and the grid.
void tileRange(const Reachable& c, const int64_t t0[3], const std::array<std::vector<double>, 3>& centres,
               int64_t lo[3], int64_t hi[3]) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(c.cells[a][0], t0[a]);
    hi[a] = std::min({c.cells[a][1], t0[a] + int64_t(kTile) - 1, int64_t(centres[a].size()) - 1});
  }
}

// Every cell of primitive p's reach box in the tile: visit(its slot of `nearest`, its centre). The boxes route takes
// every primitive this way, the scan route the spheres and ellipsoids.
template <typename Visit>
void forCellsInReach(const Primitives& primitives, size_t p, const int64_t t0[3], std::vector<double>& nearest,
                     const Visit& visit) {
  const auto& centres = primitives.centres;
  int64_t lo[3], hi[3];
  tileRange(primitives.reach(p), t0, centres, lo, hi);
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i)
        visit(nearest[tileIndex(i - t0[0], j - t0[1], k - t0[2])],
              Vec3{centres[0][size_t(i)], centres[1][size_t(j)], centres[2][size_t(k)]});
}

double squaredDistanceToShape(const Primitives& primitives, size_t shape, const Vec3& c) {
  const Vec3 d = c - closestPointOnEllipsoid(primitives.shapes[shape], c);
  return dot(d, d);
}

}  // namespace

void TileEvaluator::evaluate(const Primitives& primitives, Route route, const int64_t t0[3], const uint32_t* prims,
                             size_t count, std::vector<double>& nearest) {
  nearest.assign(size_t(kTile) * kTile * kTile, INFINITY);
  if (route == Route::kBoxes)
    boxes(primitives, t0, prims, count, nearest);
  else
    scan(primitives, t0, prims, count, nearest);
}

void TileEvaluator::boxes(const Primitives& primitives, const int64_t t0[3], const uint32_t* prims, size_t count,
                          std::vector<double>& nearest) {
  const size_t triangles = primitives.scene.triangles.size();
  for (size_t q = 0; q < count; ++q) {
    const size_t p = prims[q];
    const TriangleLowerBound bound =
        p < triangles ? triangleLowerBound(primitives.scene.triangles[p]) : TriangleLowerBound{};
    forCellsInReach(primitives, p, t0, nearest, [&](double& slot, const Vec3& c) {
      const double d2 = p < triangles ? squaredDistanceToTriangleWithin(primitives.scene.triangles[p], bound, c,
                                                                        std::min(slot, primitives.reach2))
                                      : squaredDistanceToShape(primitives, p - triangles, c);
      if (d2 < slot) slot = d2;
    });
  }
}

void TileEvaluator::scan(const Primitives& primitives, const int64_t t0[3], const uint32_t* prims, size_t count,
                         std::vector<double>& nearest) {
  const Scene& scene = primitives.scene;
  const auto& centres = primitives.centres;
  const size_t triangles = scene.triangles.size();
  smallest_.assign(nearest.size(), INFINITY);
  nearestTriangle_.assign(nearest.size(), std::numeric_limits<uint32_t>::max());
  runs_.clear();
  size_t used = 0;  // of lowerBounds_
  // The tile's x centres, one more past the last (rowLowerBounds reads pairs).
  std::array<double, kTile + 2> xs;
  for (size_t i = 0; i < xs.size(); ++i) xs[i] = centres[0][std::min(size_t(t0[0]) + i, centres[0].size() - 1)];
  // Pass 1: each triangle's rows, their cells' lower bounds, and each cell's smallest.
  for (size_t q = 0; q < count; ++q) {
    const uint32_t p = prims[q];
    if (p >= triangles) continue;
    const Triangle& t = scene.triangles[p];
    const TriangleLowerBound bound = triangleLowerBound(t);
    const Reachable reach = primitives.reach(p);
    const RowScan rows = primitives.rows(p, bound, reach);
    const Vec3& a = t.v[0];
    int64_t lo[3], hi[3];
    tileRange(reach, t0, centres, lo, hi);
    for (int64_t k = lo[2]; k <= hi[2]; ++k) {
      const double z = centres[2][size_t(k)], rz = z - a.z;
      for (int64_t j = lo[1]; j <= hi[1]; ++j) {
        const double y = centres[1][size_t(j)], ry = y - a.y;
        double ulo = -INFINITY, uhi = INFINITY;
        int e = 0;
        for (; e < rows.upper; ++e) {
          const RowScan::Constraint& c = rows.constraints[size_t(e)];
          uhi = std::min(uhi, (c.c0 - c.cy * ry - c.cz * rz) * c.inverse);
        }
        for (; e < rows.lower; ++e) {
          const RowScan::Constraint& c = rows.constraints[size_t(e)];
          ulo = std::max(ulo, (c.c0 - c.cy * ry - c.cz * rz) * c.inverse);
        }
        bool empty = !(ulo <= uhi);
        for (; e < rows.count && !empty; ++e) {
          const RowScan::Constraint& c = rows.constraints[size_t(e)];
          empty = c.c0 - c.cy * ry - c.cz * rz + std::fabs(c.cx) * rows.dxMax < 0;
        }
        if (empty) continue;
        // The first and last centre of the row within [ulo, uhi] (relative to a.x), counted without branches.
        int64_t i0 = lo[0], i1 = hi[0];
        for (int64_t i = lo[0]; i <= hi[0]; ++i) {
          const double u = xs[size_t(i - t0[0])] - a.x;
          i0 += u < ulo;
          i1 -= u > uhi;
        }
        if (i0 > i1) continue;
        const size_t first = tileIndex(i0 - t0[0], j - t0[1], k - t0[2]), n = size_t(i1 - i0 + 1);
        runs_.push_back({p, uint16_t(first), uint16_t(n)});
        if (lowerBounds_.size() < used + n + 1) lowerBounds_.resize(2 * (used + n + 1));
        double* lb = lowerBounds_.data() + used;
        rowLowerBounds(t, bound, xs.data() + (i0 - t0[0]), n, y, z, lb);
        for (size_t m = 0; m < n; ++m) {  // without branches: which triangle wins is a coin toss
          const bool better = lb[m] < smallest_[first + m];
          smallest_[first + m] = better ? lb[m] : smallest_[first + m];
          nearestTriangle_[first + m] = better ? p : nearestTriangle_[first + m];
        }
        used += n;
      }
    }
  }
  const auto centre = [&](size_t slot) {
    return Vec3{centres[0][size_t(t0[0]) + slot % kTile], centres[1][size_t(t0[1]) + slot / kTile % kTile],
                centres[2][size_t(t0[2]) + slot / (kTile * kTile)]};
  };
  // Pass 2: the exact distance of the triangle of smallest bound, nearly always the nearest.
  for (size_t slot = 0; slot < nearest.size(); ++slot) {
    if (!(smallest_[slot] <= primitives.reach2)) continue;
    const Triangle& t = scene.triangles[nearestTriangle_[slot]];
    nearest[slot] = squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], centre(slot));
  }
  // Pass 3: every other triangle whose bound does not exceed the distance so far (or the reach).
  size_t b = 0;
  for (const Run& run : runs_) {
    const Triangle& t = scene.triangles[run.triangle];
    for (size_t slot = run.first; slot < size_t(run.first) + run.count; ++slot, ++b) {
      if (lowerBounds_[b] > std::min(nearest[slot], primitives.reach2)) continue;  // most pairs
      if (nearestTriangle_[slot] == run.triangle) continue;
      const double d2 = squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], centre(slot));
      if (d2 < nearest[slot]) nearest[slot] = d2;
    }
  }
  // The shapes: every cell of the reach box, as the boxes route.
  for (size_t q = 0; q < count; ++q) {
    const size_t p = prims[q];
    if (p < triangles) continue;
    forCellsInReach(primitives, p, t0, nearest, [&](double& slot, const Vec3& c) {
      const double d2 = squaredDistanceToShape(primitives, p - triangles, c);
      if (d2 < slot) slot = d2;
    });
  }
}

}  // namespace vox::band
