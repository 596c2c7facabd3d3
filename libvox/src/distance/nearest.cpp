#include "vox/distance/nearest.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>

namespace vox {

namespace {

constexpr uint32_t kLeafSize = 4;

Box unite(const Box& a, const Box& b) { return {minVec(a.lo, b.lo), maxVec(a.hi, b.hi)}; }

// A lower bound of the squared distance from p to anything inside the box: the box's own distance, less a rounding
// allowance (the axes are orthonormal only to rounding, and the projections round relative to |p - centre|).
double squaredDistanceToOrientedBox(const NearestPrimitive::OrientedBox& b, const Vec3& p) {
  const Vec3 d = p - b.centre;
  const double err = 1e-13 * (std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z));
  double sum = 0;
  for (int a = 0; a < 3; ++a) {
    const double outside = std::fabs(dot(b.axes[a], d)) - b.half[a] - err;
    const double e = outside > 0 ? outside : 0.0;  // a maxsd, where std::max's NaN rules make a branch
    sum += e * e;
  }
  return sum * (1 - 1e-12);
}

// The points whose convex hull holds primitive `id`: a triangle's corners, the corners of a sphere's box.
template <typename Visit>
void forHullPoints(const Scene& scene, const std::vector<Box>& boxes, uint32_t id, const Visit& visit) {
  if (id < scene.triangles.size()) {
    for (const Vec3& v : scene.triangles[id].v) visit(v);
    return;
  }
  const Box& b = boxes[id];
  for (int c = 0; c < 8; ++c) visit(Vec3{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z});
}

}  // namespace

NearestPrimitive::NearestPrimitive(const Scene& scene, const PowerOfTwoFrame& frame)
    : NearestPrimitive(sceneInFrame(scene, frame)) {
  frame_ = frame;
}

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
    std::vector<std::array<uint32_t, 2>> ranges;  // each node's slots
    build(0, uint32_t(n), centroids, ranges, 0);
    // Each box depends only on its node's slots: all of them at once.
    tbb::parallel_for(size_t(0), nodes_.size(),
                      [&](size_t i) { nodes_[i].box = orientedBounds(ranges[i][0], ranges[i][1], scene, boxes); });
  }
  // Triangles copied in leaf order, so a leaf's are adjacent in memory.
  triangles_.resize(n);
  bounds_.resize(n);
  slotOf_.resize(n);
  leafOf_.resize(n);
  for (uint32_t i = 0; i < nodes_.size(); ++i)
    for (uint32_t s = nodes_[i].first; s < nodes_[i].first + nodes_[i].count; ++s) leafOf_[s] = i;
  for (size_t s = 0; s < n; ++s) slotOf_[ids_[s]] = uint32_t(s);
  for (size_t s = 0; s < n; ++s)
    if (ids_[s] < triangleCount_) {
      const Triangle& t = scene.triangles[ids_[s]];
      triangles_[s] = t;
      bounds_[s] = triangleLowerBound(t);
    }
}

// The oriented box of the primitives in slots [begin, end): the principal axes of their hull points (a tight slab
// around a flat patch, where an axis-aligned box leaves a wide margin), its extents taken about the final centre and
// widened for the projections' rounding, so that every point of every primitive lies inside.
NearestPrimitive::OrientedBox NearestPrimitive::orientedBounds(uint32_t begin, uint32_t end, const Scene& scene,
                                                               const std::vector<Box>& boxes) const {
  Vec3 sum{0, 0, 0};
  double count = 0;
  for (uint32_t s = begin; s < end; ++s)
    forHullPoints(scene, boxes, ids_[s], [&](const Vec3& q) { sum = sum + q, ++count; });
  const Vec3 mean = sum / count;
  std::array<std::array<double, 3>, 3> covariance{};
  for (uint32_t s = begin; s < end; ++s)
    forHullPoints(scene, boxes, ids_[s], [&](const Vec3& q) {
      const Vec3 d = q - mean;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) covariance[i][j] += d[i] * d[j];
    });
  OrientedBox box;
  box.axes = symmetricEigenvectors(covariance);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi = lo * -1.0;
  for (uint32_t s = begin; s < end; ++s)
    forHullPoints(scene, boxes, ids_[s], [&](const Vec3& q) {
      for (int a = 0; a < 3; ++a) {
        const double u = dot(box.axes[a], q - mean);
        lo.at(a) = std::min(lo[a], u), hi.at(a) = std::max(hi[a], u);
      }
    });
  box.centre = mean;
  for (int a = 0; a < 3; ++a) box.centre = box.centre + box.axes[a] * (0.5 * (lo[a] + hi[a]));
  box.half = {0, 0, 0};
  for (uint32_t s = begin; s < end; ++s)
    forHullPoints(scene, boxes, ids_[s], [&](const Vec3& q) {
      for (int a = 0; a < 3; ++a) box.half.at(a) = std::max(box.half[a], std::fabs(dot(box.axes[a], q - box.centre)));
    });
  const double widen = 1e-12 * (box.half.x + box.half.y + box.half.z);
  for (int a = 0; a < 3; ++a) box.half.at(a) = box.half[a] * (1 + 1e-12) + widen;
  return box;
}

// Median split of the centroids on the longest axis of their spread: balanced, and built in O(n log n).
uint32_t NearestPrimitive::build(uint32_t begin, uint32_t end, const std::vector<Vec3>& centroids,
                                 std::vector<std::array<uint32_t, 2>>& ranges, uint32_t parent) {
  const uint32_t index = uint32_t(nodes_.size());
  nodes_.push_back({});
  ranges.push_back({begin, end});
  nodes_[index].parent = parent;
  Box spread{centroids[ids_[begin]], centroids[ids_[begin]]};
  for (uint32_t s = begin + 1; s < end; ++s) spread = unite(spread, {centroids[ids_[s]], centroids[ids_[s]]});
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
  build(begin, mid, centroids, ranges, index);
  nodes_[index].first = build(mid, end, centroids, ranges, index);
  return index;
}

// The squared distance from p to the primitive in `slot`, or infinity when a triangle's plane alone is farther
// than bound2 (squaredDistanceToTriangleWithin).
double NearestPrimitive::squaredDistanceTo(uint32_t slot, const Vec3& p, double bound2) const {
  const uint32_t id = ids_[slot];
  if (id < triangleCount_) return squaredDistanceToTriangleWithin(triangles_[slot], bounds_[slot], p, bound2);
  const Vec3 d = p - closestPointOnEllipsoid(shapes_[id - triangleCount_], p);
  return dot(d, d);
}

// From the seed's leaf up: at each ancestor, the subtree on the other side is searched (most are pruned by their
// box alone). Near answers lie in near subtrees, so this tests fewer boxes than a descent from the root.
NearestHit NearestPrimitive::nearestFrom(const Vec3& p, int64_t seed) const {
  if (seed < 0 || uint64_t(seed) >= ids_.size()) return nearest(p);
  // The seed's leaf first, the seed among its primitives: its distance becomes the bound.
  NearestHit best;
  uint32_t node = leafOf_[slotOf_[size_t(seed)]];
  visitLeaf(nodes_[node], p, best);
  while (node != 0) {
    const uint32_t parent = nodes_[node].parent;
    search(p, best, node == parent + 1 ? nodes_[parent].first : parent + 1);
    node = parent;
  }
  return best;
}

NearestHit NearestPrimitive::nearest(const Vec3& p, double bound2) const {
  NearestHit best;
  best.squaredDistance = bound2;
  if (!nodes_.empty()) search(p, best, 0);
  if (best.primitive < 0) best.squaredDistance = INFINITY;
  return best;
}

void NearestPrimitive::visitLeaf(const Node& leaf, const Vec3& p, NearestHit& best) const {
  for (uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
    const double d2 = squaredDistanceTo(s, p, best.squaredDistance);
    const int64_t id = ids_[s];
    if (d2 < best.squaredDistance || (d2 == best.squaredDistance && (best.primitive < 0 || id < best.primitive))) {
      best.squaredDistance = d2;
      best.primitive = id;
    }
  }
}

// Lowers `best` to the nearest primitive of the subtree at `root` within it (ties to the lowest id): every subtree
// whose box is no farther than the best so far is visited, nearer child first.
void NearestPrimitive::search(const Vec3& p, NearestHit& best, uint32_t root) const {
  // Depth is about log2(n / kLeafSize) + 1 for a median split: 64 holds any 32-bit count. Each waiting subtree
  // keeps its box's squared distance, so that it is tested again without recomputing it.
  struct Waiting {
    uint32_t node;
    double d2;
  };
  std::array<Waiting, 64> stack;
  size_t top = 0;
  uint32_t current = root;
  double currentD2 = squaredDistanceToOrientedBox(nodes_[root].box, p);
  for (;;) {
    if (currentD2 <= best.squaredDistance) {
      const Node& node = nodes_[current];
      if (node.count == 0) {
        const uint32_t a = current + 1, b = node.first;
        const double da = squaredDistanceToOrientedBox(nodes_[a].box, p),
                     db = squaredDistanceToOrientedBox(nodes_[b].box, p);
        const bool aFirst = da <= db;
        stack[top++] = {aFirst ? b : a, aFirst ? db : da};  // the farther child waits
        current = aFirst ? a : b;
        currentD2 = aFirst ? da : db;
        continue;
      }
      visitLeaf(node, p, best);
    }
    if (top == 0) return;
    --top;
    current = stack[top].node;
    currentD2 = stack[top].d2;
  }
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
