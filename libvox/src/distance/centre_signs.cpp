#include "vox/distance/centre_signs.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

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
  const int o = orient2d(a.y, a.z, b.y, b.z, c.y, c.z);
  if (o == 0) return 0;
  if (perturbedOrient(a, b, qy, qz) != o || perturbedOrient(b, c, qy, qz) != o || perturbedOrient(c, a, qy, qz) != o)
    return 0;
  return o;
}

constexpr uint32_t kLineLeaf = 4;

}  // namespace

InsideTest::InsideTest(const Scene& scene) { build(scene); }

InsideTest::InsideTest(const Scene& scene, const PowerOfTwoFrame& frame)
    : framed_(std::make_shared<const Scene>(sceneInFrame(scene, frame))), frame_(frame) {
  build(*framed_);
}

void InsideTest::build(const Scene& scene) {
  shapes_.reserve(scene.spheres.size());
  for (const Sphere& s : scene.spheres) shapes_.push_back(ellipsoidShape(s));
  if (scene.triangles.empty()) return;
  boundaries_ = openBoundaries({scene.triangles.data(), scene.triangles.size()}, nullptr, kMaxCapBoundaries);
  counted_ = boundaries_.size() <= kMaxCapBoundaries;
  if (!counted_) {  // a soup: the winding tree
    boundaries_.clear();
    tree_ = buildWindingTree({scene.triangles.data(), scene.triangles.size()});
    return;
  }
  mesh_ = {scene.triangles.data(), scene.triangles.size()};
  for (const OpenBoundary& b : boundaries_) caps_.insert(caps_.end(), b.cap.begin(), b.cap.end());
  capTree_ = buildWindingTree({caps_.data(), caps_.size()});
  const size_t count = mesh_.size() + caps_.size();
  if (count > UINT32_MAX) fail<LimitError>("inside test: more than 2^32 - 1 triangles with the caps");
  // Triangles edge-on to x are never crossed: left out of the tree.
  for (uint32_t t = 0; t < count; ++t) {
    const Vec3 &a = triangle(t).v[0], &b = triangle(t).v[1], &c = triangle(t).v[2];
    if (orient2d(a.y, a.z, b.y, b.z, c.y, c.z) != 0) order_.push_back(t);
  }
  if (!order_.empty()) buildLineTree(0, uint32_t(order_.size()));
}

// Median split of order_[begin, end) on the longer axis of the (y, z) centroids; depth first, so the first child
// follows its parent.
uint32_t InsideTest::buildLineTree(uint32_t begin, uint32_t end) {
  const uint32_t index = uint32_t(lineNodes_.size());
  lineNodes_.push_back({});
  LineNode n{{INFINITY, INFINITY}, {-INFINITY, -INFINITY}, begin, 0};
  double clo[2] = {INFINITY, INFINITY}, chi[2] = {-INFINITY, -INFINITY};
  for (uint32_t s = begin; s < end; ++s)
    for (const int a : {0, 1}) {
      const Triangle& t = triangle(order_[s]);
      const double u = t.v[0][a + 1], v = t.v[1][a + 1], w = t.v[2][a + 1];
      n.lo[a] = std::min({n.lo[a], u, v, w});
      n.hi[a] = std::max({n.hi[a], u, v, w});
      clo[a] = std::min(clo[a], u + v + w);
      chi[a] = std::max(chi[a], u + v + w);
    }
  if (end - begin <= kLineLeaf) {
    n.count = end - begin;
    lineNodes_[index] = n;
    return index;
  }
  const int axis = chi[0] - clo[0] >= chi[1] - clo[1] ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t p, uint32_t q) {
    const Triangle &a = triangle(p), &b = triangle(q);
    return a.v[0][axis] + a.v[1][axis] + a.v[2][axis] < b.v[0][axis] + b.v[1][axis] + b.v[2][axis];
  });
  buildLineTree(begin, mid);
  n.first = buildLineTree(mid, end);
  lineNodes_[index] = n;
  return index;
}

void InsideTest::rowCrossings(double qy, double qz, std::vector<Crossing>& out) const {
  out.clear();
  if (lineNodes_.empty()) return;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const LineNode& n = lineNodes_[stack[--top]];
    if (qy < n.lo[0] || qy > n.hi[0] || qz < n.lo[1] || qz > n.hi[1]) continue;
    if (n.count == 0) {
      const uint32_t self = uint32_t(&n - lineNodes_.data());
      stack[top++] = n.first;
      stack[top++] = self + 1;
      continue;
    }
    for (uint32_t s = n.first; s < n.first + n.count; ++s) {
      const Triangle& t = triangle(order_[s]);
      if (qy < std::min({t.v[0].y, t.v[1].y, t.v[2].y}) || qy > std::max({t.v[0].y, t.v[1].y, t.v[2].y}) ||
          qz < std::min({t.v[0].z, t.v[1].z, t.v[2].z}) || qz > std::max({t.v[0].z, t.v[1].z, t.v[2].z}))
        continue;  // the perturbed line cannot cross it either
      if (const int sign = rowLineCrossing(t, qy, qz))
        out.push_back(
            {order_[s], sign, std::min({t.v[0].x, t.v[1].x, t.v[2].x}), std::max({t.v[0].x, t.v[1].x, t.v[2].x})});
    }
  }
}

bool InsideTest::inside(const Vec3& p, const std::vector<Crossing>& crossings) const {
  for (const EllipsoidShape& s : shapes_)
    if (insideEllipsoid(s, p)) return true;
  if (!counted_)
    return !tree_.nodes.empty() &&
           std::fabs(windingNumberToDecide(tree_, p, 0, kWindingThreshold)) >= kWindingThreshold;
  // Crossing towards +x a triangle whose normal has x sign s changes the winding number by -s; the crossing lies
  // before p when p is on the side of the plane the normal's x component points to.
  int64_t k = 0;
  bool onCap = false;
  for (const Crossing& x : crossings) {
    if (p.x < x.xlo) continue;
    int side = x.sign;
    if (p.x <= x.xhi) {
      const Triangle& t = triangle(x.triangle);
      side = orient3d(t.v[0], t.v[1], t.v[2], p);
      // On a mesh triangle p is on the surface (distance 0, unsigned); on a cap, k and s both jump there.
      if (side == 0 && x.triangle >= mesh_.size()) onCap = true;
    }
    if (side == x.sign) k -= x.sign;
  }
  if (onCap) return std::fabs(windingNumberExact(mesh_, p)) >= kWindingThreshold;
  if (capWindingBound(boundaries_, Box{p, p}) < kCapBoundForInteger) return k != 0;
  // The caps' tree first (beta 2: errors of about 1e-3, and 0.03 seen at worst on grazing views); the exact sum
  // over the caps' triangles only where |k - s| lies within kExactMargin of the threshold.
  constexpr double kExactMargin = 0.25;
  const double rough = std::fabs(double(k) - windingNumber(capTree_, p));
  if (std::fabs(rough - kWindingThreshold) > kExactMargin) return rough >= kWindingThreshold;
  const double s = windingNumberExact({caps_.data(), caps_.size()}, p);
  return std::fabs(double(k) - s) >= kWindingThreshold;
}

bool InsideTest::inside(const Vec3& p) const {
  thread_local std::vector<Crossing> crossings;
  if (counted_) rowCrossings(p.y, p.z, crossings);
  return inside(p, crossings);
}

std::vector<uint8_t> centresInside(const Grid& grid, const InsideTest& test, std::span<const uint64_t> keys,
                                   const std::function<bool(double)>& progress) {
  std::vector<uint8_t> inside(keys.size(), 0);
  // Rows along x: [first, end) ranges of `keys` indices.
  std::vector<std::pair<size_t, size_t>> rows;
  for (size_t c = 0; c < keys.size();) {
    const uint64_t row = keys[c] / grid.dims[0];
    size_t e = c + 1;
    while (e < keys.size() && keys[e] / grid.dims[0] == row) ++e;
    rows.push_back({c, e});
    c = e;
  }
  const std::array<std::vector<double>, 3> centres = cellCentresByAxis(grid);
  std::atomic<size_t> done{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled) return;
    std::vector<InsideTest::Crossing> crossings;
    for (size_t row = r.begin(); row < r.end(); ++row) {
      const auto [first, end] = rows[row];
      const auto ijk = cellIndex(grid.dims, keys[first]);
      const double qy = centres[1][ijk[1]], qz = centres[2][ijk[2]];
      test.rowCrossings(qy, qz, crossings);
      for (size_t c = first; c < end; ++c)
        inside[c] = test.inside({centres[0][keys[c] % grid.dims[0]], qy, qz}, crossings);
    }
    const size_t finished = done += r.size();
    if (progress && !progress(double(finished) / double(std::max<size_t>(rows.size(), 1)))) cancelled = true;
  });
  if (cancelled) fail<Error>("signed distances cancelled");
  return inside;
}

std::vector<uint8_t> occupiedCentresInside(const Grid& grid, const Scene& scene,
                                           const std::function<bool(double)>& progress) {
  const InsideTest test(scene);
  return centresInside(grid, test, {grid.cellKeys.data(), grid.cellKeys.size()}, progress);
}

}  // namespace vox
