#include "vox/distance/centre_signs.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include "vox/core/error.h"
#include "vox/core/exact_orient.h"
#include "vox/distance/closest_point.h"
#include "vox/distance/sdf.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/winding_number.h"

namespace vox {

namespace {

// Sign of orient2d(u, v, q) in the (y, z) plane with q moved to (qy + e, qz + e^2), e infinitesimal: the rounded-off
// first-order terms decide where q lies on the line through u and v. 0 only when u and v project to one point.
int perturbedOrient(const Vec3& u, const Vec3& v, double qy, double qz) {
  const int o = orient2d(u.y, u.z, v.y, v.z, qy, qz);
  if (o != 0) return o;
  // (v.y - u.y)(qz - u.z) - (v.z - u.z)(qy - u.y): its derivative in qy is u.z - v.z, in qz v.y - u.y.
  if (u.z != v.z) return u.z > v.z ? 1 : -1;
  return v.y > u.y ? 1 : (v.y < u.y ? -1 : 0);
}

// Whether the line (y, z) = (qy, qz) along x, perturbed as above, crosses triangle t: the sign of the x component
// of its normal (b - a) x (c - a) when it does, 0 when it misses. A triangle edge-on to x is always missed.
int rowLineCrossing(const Triangle& t, double qy, double qz) {
  const Vec3 &a = t.v[0], &b = t.v[1], &c = t.v[2];
  if (qy < std::min({a.y, b.y, c.y}) || qy > std::max({a.y, b.y, c.y}) || qz < std::min({a.z, b.z, c.z}) ||
      qz > std::max({a.z, b.z, c.z}))
    return 0;
  const int o = orient2d(a.y, a.z, b.y, b.z, c.y, c.z);
  if (o == 0) return 0;
  if (perturbedOrient(a, b, qy, qz) != o || perturbedOrient(b, c, qy, qz) != o || perturbedOrient(c, a, qy, qz) != o)
    return 0;
  return o;
}

struct RowCrossing {
  const Triangle* triangle;
  int sign;  // of the normal's x component
};

// The caps that close the mesh's holes, with their winding tree.
struct CapWinding {
  std::vector<OpenBoundary> boundaries;
  WindingTree tree;
  // s at p, close enough to decide |k - s| >= kWindingThreshold as the exact value does. Far from every hole the
  // bound on |s| leaves k alone to decide, and 0 stands in for s.
  double at(const Vec3& p, int64_t k) const {
    if (tree.nodes.empty() || capWindingBound(boundaries, Box{p, p}) < kCapBoundForInteger) return 0;
    return windingNumberToDecide(tree, p, double(k), kWindingThreshold);
  }
};

// Rows of the grid along x that hold occupied cells: [first, end) ranges of cellKeys indices.
std::vector<std::pair<size_t, size_t>> occupiedRows(const Grid& grid) {
  std::vector<std::pair<size_t, size_t>> rows;
  const size_t n = grid.cellKeys.size();
  for (size_t c = 0; c < n;) {
    const uint64_t row = grid.cellKeys[c] / grid.dims[0];
    size_t e = c + 1;
    while (e < n && grid.cellKeys[e] / grid.dims[0] == row) ++e;
    rows.push_back({c, e});
    c = e;
  }
  return rows;
}

template <typename Body>
void forEachCentreBlock(size_t count, const std::function<bool(double)>& progress, const Body& body) {
  std::atomic<size_t> done{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 256), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled) return;
    body(r);
    const size_t finished = done += r.size();
    if (progress && !progress(double(finished) / double(std::max<size_t>(count, 1)))) cancelled = true;
  });
  if (cancelled) fail<Error>("signed distances cancelled");
}

}  // namespace

std::vector<uint8_t> occupiedCentresInside(const Grid& grid, const Scene& scene,
                                           const std::function<bool(double)>& progress) {
  std::vector<uint8_t> inside(grid.occupiedCount(), 0);
  std::optional<CapWinding> caps;
  if (grid.method != OverlapMethod::Center && grid.outsidePrims.empty()) {
    std::vector<OpenBoundary> boundaries = openBoundaries(scene.triangles, nullptr, kMaxCapBoundaries);
    if (boundaries.size() <= kMaxCapBoundaries) {
      caps.emplace();
      std::vector<Triangle> capTriangles;
      for (const OpenBoundary& b : boundaries) capTriangles.insert(capTriangles.end(), b.cap.begin(), b.cap.end());
      caps->tree = buildWindingTree(capTriangles);
      caps->boundaries = std::move(boundaries);
    }
  }
  const std::array<std::vector<double>, 3> centres = cellCentresByAxis(grid);
  if (!caps) {  // no exact count: the whole mesh's tree at each centre
    const InsideTest insideTest(scene);
    forEachCentreBlock(inside.size(), progress, [&](const tbb::blocked_range<size_t>& r) {
      for (size_t c = r.begin(); c < r.end(); ++c) inside[c] = insideTest.inside(cellCentre(grid, grid.cellKeys[c]));
    });
    return inside;
  }
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& s : scene.spheres) shapes.push_back(ellipsoidShape(s));
  const std::vector<std::pair<size_t, size_t>> rows = occupiedRows(grid);
  forEachCentreBlock(rows.size(), progress, [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> ids;
    std::vector<RowCrossing> crossings;
    for (size_t row = r.begin(); row < r.end(); ++row) {
      const auto [first, end] = rows[row];
      const auto ijk = cellIndex(grid.dims, grid.cellKeys[first]);
      const double qy = centres[1][ijk[1]], qz = centres[2][ijk[2]];
      ids.clear();
      for (size_t c = first; c < end; ++c)
        for (const uint32_t id : grid.cellPrims(c))
          if (id < scene.triangles.size()) ids.push_back(id);
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      crossings.clear();
      for (const uint32_t id : ids)
        if (const int s = rowLineCrossing(scene.triangles[id], qy, qz)) crossings.push_back({&scene.triangles[id], s});
      for (const OpenBoundary& b : caps->boundaries) {
        if (qy < b.bounds.lo.y || qy > b.bounds.hi.y || qz < b.bounds.lo.z || qz > b.bounds.hi.z) continue;
        for (const Triangle& t : b.cap)
          if (const int s = rowLineCrossing(t, qy, qz)) crossings.push_back({&t, s});
      }
      for (size_t c = first; c < end; ++c) {
        const Vec3 p{centres[0][cellIndex(grid.dims, grid.cellKeys[c])[0]], qy, qz};
        bool in = false;
        for (const EllipsoidShape& shape : shapes) in = in || insideEllipsoid(shape, p);
        if (!in) {
          // Crossing towards +x a triangle whose normal has x sign s changes the winding number by -s; the crossing
          // lies before p when p is on the side of the plane the normal's x component points to.
          int64_t k = 0;
          for (const RowCrossing& x : crossings)
            if (orient3d(x.triangle->v[0], x.triangle->v[1], x.triangle->v[2], p) == x.sign) k -= x.sign;
          in = std::abs(double(k) - caps->at(p, k)) >= kWindingThreshold;
        }
        inside[c] = in;
      }
    }
  });
  return inside;
}

}  // namespace vox
