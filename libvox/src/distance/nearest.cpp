#include "vox/distance/nearest.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace vox {

namespace {

constexpr uint32_t kLeafSize = 4;

double squaredDistanceToBox(const Box& b, const Vec3& p) {
  double sum = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({b.lo[a] - p[a], 0.0, p[a] - b.hi[a]});
    sum += d * d;
  }
  return sum;
}

Box unite(const Box& a, const Box& b) { return {minVec(a.lo, b.lo), maxVec(a.hi, b.hi)}; }

}  // namespace

NearestPrimitive::NearestPrimitive(const Scene& scene) : triangleCount_(uint32_t(scene.triangles.size())) {
  const size_t n = scene.triangles.size() + scene.spheres.size();
  for (const Sphere& s : scene.spheres) shapes_.push_back(ellipsoidShape(s));
  std::vector<Box> boxes(n);
  std::vector<Vec3> centroids(n);
  for (size_t p = 0; p < n; ++p) {
    boxes[p] = p < triangleCount_ ? triangleBounds(scene.triangles[p]) : ellipsoidBounds(shapes_[p - triangleCount_]);
    centroids[p] = (boxes[p].lo + boxes[p].hi) * 0.5;
  }
  ids_.resize(n);
  std::iota(ids_.begin(), ids_.end(), 0u);
  if (n > 0) {
    nodes_.reserve(2 * (n / kLeafSize + 1));
    build(0, uint32_t(n), centroids, boxes);
  }
  // Triangles copied in leaf order, so a leaf's are adjacent in memory.
  triangles_.resize(n);
  normals_.resize(n);
  slotOf_.resize(n);
  for (size_t s = 0; s < n; ++s) slotOf_[ids_[s]] = uint32_t(s);
  for (size_t s = 0; s < n; ++s)
    if (ids_[s] < triangleCount_) {
      const Triangle& t = scene.triangles[ids_[s]];
      triangles_[s] = t;
      normals_[s] = cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
    }
}

// Median split of the centroids on the box's longest axis: balanced, and built in O(n log n).
uint32_t NearestPrimitive::build(uint32_t begin, uint32_t end, std::vector<Vec3>& centroids, std::vector<Box>& boxes) {
  const uint32_t index = uint32_t(nodes_.size());
  nodes_.push_back({});
  Box box = boxes[ids_[begin]], spread{centroids[ids_[begin]], centroids[ids_[begin]]};
  for (uint32_t s = begin + 1; s < end; ++s) {
    box = unite(box, boxes[ids_[s]]);
    spread = unite(spread, {centroids[ids_[s]], centroids[ids_[s]]});
  }
  nodes_[index].box = box;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  const Vec3 extent = spread.hi - spread.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(ids_.begin() + begin, ids_.begin() + mid, ids_.begin() + end, [&](uint32_t a, uint32_t b) {
    return centroids[a][axis] != centroids[b][axis] ? centroids[a][axis] < centroids[b][axis] : a < b;
  });
  build(begin, mid, centroids, boxes);
  nodes_[index].first = build(mid, end, centroids, boxes);
  return index;
}

// The squared distance from p to the primitive in `slot`, or infinity when a triangle's plane alone is farther
// than bound2 (squaredDistanceToTriangleWithin).
double NearestPrimitive::squaredDistanceTo(uint32_t slot, const Vec3& p, double bound2) const {
  const uint32_t id = ids_[slot];
  if (id < triangleCount_) return squaredDistanceToTriangleWithin(triangles_[slot], normals_[slot], p, bound2);
  const Vec3 d = p - closestPointOnEllipsoid(shapes_[id - triangleCount_], p);
  return dot(d, d);
}

NearestHit NearestPrimitive::nearest(const Vec3& p, double bound2) const {
  NearestHit best;
  best.squaredDistance = bound2;
  if (nodes_.empty()) return {};
  // Depth is about log2(n / kLeafSize) + 1 for a median split: 64 holds any 32-bit count.
  std::array<uint32_t, 64> stack;
  size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (squaredDistanceToBox(node.box, p) > best.squaredDistance) continue;
    if (node.count > 0) {
      for (uint32_t s = node.first; s < node.first + node.count; ++s) {
        const double d2 = squaredDistanceTo(s, p, best.squaredDistance);
        const int64_t id = ids_[s];
        if (d2 < best.squaredDistance || (d2 == best.squaredDistance && (best.primitive < 0 || id < best.primitive))) {
          best.squaredDistance = d2;
          best.primitive = id;
        }
      }
      continue;
    }
    const uint32_t a = uint32_t(&node - nodes_.data()) + 1, b = node.first;
    const double da = squaredDistanceToBox(nodes_[a].box, p), db = squaredDistanceToBox(nodes_[b].box, p);
    stack[top++] = da <= db ? b : a;  // the farther child waits
    stack[top++] = da <= db ? a : b;
  }
  if (best.primitive < 0) best.squaredDistance = INFINITY;
  return best;
}

Vec3 NearestPrimitive::closestPoint(int64_t id, const Vec3& p) const {
  if (id < 0 || uint64_t(id) >= ids_.size()) return {NAN, NAN, NAN};
  if (id < triangleCount_) {
    const Triangle& t = triangles_[slotOf_[size_t(id)]];
    return closestPointOnTriangle(t.v[0], t.v[1], t.v[2], p);
  }
  return closestPointOnEllipsoid(shapes_[size_t(id) - triangleCount_], p);
}

}  // namespace vox
