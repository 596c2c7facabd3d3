#include "vox/distance/nearest.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include <emmintrin.h>
#include <tbb/parallel_for.h>

namespace vox {

namespace {

constexpr uint32_t kLeafSize = 4;

// The float bounds' rounding allowance, per unit of |q|_1 plus the box's or triangle's own magnitude (about the
// origin): a float conversion errs by 2^-24 of its value, and each bound is a few float operations on values that
// are no larger, so the float bound errs from the same bound in real arithmetic by at most 9 * 2^-24 of that size
// (sums, products and the conversions of q, the normals and the offsets). 2^-18 is more than four times that, so
// the allowance also covers the double route's own rounding (about 2^-50 of the same size: the exact distance
// computed relative to p, and for triangles the double bound's own allowance is added) with room to spare: a bound
// lowered by it lies strictly below the computed exact distance of every primitive it bounds, by at least a
// quarter of the allowance (a box's per-axis lowering shortens its distance vector by at least a quarter of it).
// pruneAbove then adds a relative margin for the float squares and sums, so whatever the float test skips, the
// double route would have computed and rejected (a distance above the best so far): the answer is unchanged.
// kAbsolute covers the values that underflow to subnormal floats (a scene far smaller than its distance from the
// origin). tests/nearest_test.cpp fails without these allowances.
constexpr float kRelative = 0x1p-18f;
constexpr float kAbsolute = 0x1p-100f;
// Float axes are orthonormal only to about 2^-23: a sum of squares along them may exceed the squared length by
// about 3 * 2^-23, which this factor undoes.
constexpr float kShrink = 1 - 0x1p-18f;
// Points farther than this from the origin (in the frame, where the scene's magnitude is in [1, 2)) are searched
// without float pruning: their squares would leave the float range.
constexpr double kFloatReach = 0x1p60;

Box unite(const Box& a, const Box& b) { return {minVec(a.lo, b.lo), maxVec(a.hi, b.hi)}; }

// The float at most x (at least x), one float step further out: the double x may itself have been rounded, by far
// less than a float step.
float floatBelow(double x) {
  float f = float(x);
  if (double(f) > x) f = std::nextafter(f, -INFINITY);
  return std::nextafter(f, -INFINITY);
}
float floatAbove(double x) { return -floatBelow(-x); }

// The squared distance below which a bound must lie for the search to open what it bounds, as a float rounded up:
// a float bound above it exceeds best2 (1 + 2^-21) in real arithmetic, after the float squares' and sums' own
// rounding (2^-22 relative, 2^-148 absolute), so the double route would have pruned it too. b is at least 2^-126, a
// normal float, so rounding b (1 + 2^-22) to the nearest float (at most 2^-24 of it away) gives a float above b,
// without floatAbove's nextafter on this hot path.
float pruneAbove(double best2) {
  const double b = best2 * (1 + 0x1p-20) + 0x1p-126;
  return b < double(std::numeric_limits<float>::max()) ? float(b * (1 + 0x1p-22)) : INFINITY;
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

double surfaceArea(const Box& b) {
  const Vec3 e = b.hi - b.lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
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
  triangles_.resize(n);
  bounds_.resize(n);
  slotOf_.resize(n);
  if (n == 0) return;
  std::vector<BinaryNode> nodes;
  nodes.reserve(2 * (n / kLeafSize + 1));
  build(0, uint32_t(n), centroids, nodes);
  // Triangles copied in leaf order, so a leaf's are adjacent in memory.
  for (size_t s = 0; s < n; ++s) slotOf_[ids_[s]] = uint32_t(s);
  for (size_t s = 0; s < n; ++s)
    if (ids_[s] < triangleCount_) {
      const Triangle& t = scene.triangles[ids_[s]];
      triangles_[s] = t;
      bounds_[s] = triangleLowerBound(t);
    }
  // Each node's box, children after their parent in `nodes`: from the last node back.
  std::vector<Box> nodeBoxes(nodes.size());
  for (size_t i = nodes.size(); i-- > 0;) {
    const BinaryNode& node = nodes[i];
    if (node.count == 0) {
      nodeBoxes[i] = unite(nodeBoxes[i + 1], nodeBoxes[node.first]);
      continue;
    }
    nodeBoxes[i] = boxes[ids_[node.first]];
    for (uint32_t s = node.first + 1; s < node.first + node.count; ++s)
      nodeBoxes[i] = unite(nodeBoxes[i], boxes[ids_[s]]);
  }
  origin_ = (nodeBoxes[0].lo + nodeBoxes[0].hi) * 0.5;
  // Each oriented box depends only on its node's slots: all of them at once.
  std::vector<FloatBox> floatBoxes(nodes.size());
  tbb::parallel_for(size_t(0), nodes.size(), [&](size_t i) { floatBoxes[i] = orientedBounds(nodes[i], scene, boxes); });
  wide_.reserve(nodes.size() / 3 + 1);
  leaves_.reserve(nodes.size() / 2 + 1);
  buildWide(0, nodes, nodeBoxes, floatBoxes);
}

// Median split of the centroids on the longest axis of their spread: balanced (depth at most 31 for 2^32
// primitives), and built in O(n log n).
uint32_t NearestPrimitive::build(uint32_t begin, uint32_t end, const std::vector<Vec3>& centroids,
                                 std::vector<BinaryNode>& nodes) {
  const uint32_t index = uint32_t(nodes.size());
  nodes.push_back({});
  nodes[index].begin = begin;
  nodes[index].end = end;
  if (end - begin <= kLeafSize) {
    nodes[index].first = begin;
    nodes[index].count = end - begin;
    return index;
  }
  Box spread{centroids[ids_[begin]], centroids[ids_[begin]]};
  for (uint32_t s = begin + 1; s < end; ++s) spread = unite(spread, {centroids[ids_[s]], centroids[ids_[s]]});
  const Vec3 extent = spread.hi - spread.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(ids_.begin() + begin, ids_.begin() + mid, ids_.begin() + end, [&](uint32_t a, uint32_t b) {
    return centroids[a][axis] != centroids[b][axis] ? centroids[a][axis] < centroids[b][axis] : a < b;
  });
  build(begin, mid, centroids, nodes);
  nodes[index].first = build(mid, end, centroids, nodes);
  return index;
}

// The four-wide node over binary node `index`: its children, the one of largest surface area replaced by its two
// until there are four (or only leaves), each child's box converted outward to float about origin_.
int32_t NearestPrimitive::buildWide(uint32_t index, const std::vector<BinaryNode>& nodes,
                                    const std::vector<Box>& nodeBoxes, const std::vector<FloatBox>& floatBoxes) {
  std::vector<uint32_t> children{index};
  for (;;) {
    int widest = -1;
    for (size_t c = 0; c < children.size(); ++c)
      if (nodes[children[c]].count == 0 &&
          (widest < 0 || surfaceArea(nodeBoxes[children[c]]) > surfaceArea(nodeBoxes[children[size_t(widest)]])))
        widest = int(c);
    if (widest < 0 || (children.size() > 1 && children.size() + 1 > 4)) break;
    const uint32_t inner = children[size_t(widest)];
    children[size_t(widest)] = inner + 1;
    children.insert(children.begin() + widest + 1, nodes[inner].first);
  }
  const int32_t self = int32_t(wide_.size());
  wide_.emplace_back();
  WideNode node{};  // unused lanes: a point box at the origin, masked out
  node.count = uint32_t(children.size());
  for (size_t lane = 0; lane < children.size(); ++lane) {
    const FloatBox& box = floatBoxes[children[lane]];
    float magnitude = 0;
    for (int a = 0; a < 3; ++a) {
      node.centre[a][lane] = box.centre[a];
      node.half[a][lane] = box.half[a];
      for (int i = 0; i < 3; ++i) node.axis[a][i][lane] = box.axis[a][i];
      magnitude += std::fabs(box.centre[a]) + box.half[a];
    }
    node.magnitude[lane] = magnitude * (1 + 0x1p-20f);
    const BinaryNode& child = nodes[children[lane]];
    if (child.count > 0) {
      leaves_.push_back(makeLeaf(child));
      node.child[lane] = ~int32_t(leaves_.size() - 1);
    } else {
      node.child[lane] = buildWide(children[lane], nodes, nodeBoxes, floatBoxes);
    }
  }
  wide_[size_t(self)] = node;
  return self;
}

// The oriented box of the node's primitives in float, about origin_: the principal axes of their hull points (a
// tight slab around a flat patch, where an axis-aligned box leaves a wide margin) rounded to float, the centre
// rounded to float, and the half extents measured along those float axes about that float centre in double, widened
// for the double projections' rounding and rounded up: every point of every primitive lies inside, exactly.
NearestPrimitive::FloatBox NearestPrimitive::orientedBounds(const BinaryNode& node, const Scene& scene,
                                                            const std::vector<Box>& boxes) const {
  Vec3 sum{0, 0, 0};
  double count = 0;
  const auto forPoints = [&](const auto& visit) {
    for (uint32_t s = node.begin; s < node.end; ++s) forHullPoints(scene, boxes, ids_[s], visit);
  };
  forPoints([&](const Vec3& q) { sum = sum + q, ++count; });
  const Vec3 mean = sum / count;
  std::array<std::array<double, 3>, 3> covariance{};
  forPoints([&](const Vec3& q) {
    const Vec3 d = q - mean;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) covariance[i][j] += d[i] * d[j];
  });
  const std::array<Vec3, 3> exact = symmetricEigenvectors(covariance);
  FloatBox box;
  std::array<Vec3, 3> axes;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 3; ++i) axes[size_t(a)].at(i) = box.axis[a][i] = float(exact[size_t(a)][i]);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi = lo * -1.0;
  forPoints([&](const Vec3& q) {
    for (int a = 0; a < 3; ++a) {
      const double u = dot(axes[size_t(a)], q - mean);
      lo.at(a) = std::min(lo[a], u), hi.at(a) = std::max(hi[a], u);
    }
  });
  Vec3 centre = mean - origin_;
  for (int a = 0; a < 3; ++a) centre = centre + axes[size_t(a)] * (0.5 * (lo[a] + hi[a]));
  for (int a = 0; a < 3; ++a) centre.at(a) = box.centre[a] = float(centre[a]);
  Vec3 half{0, 0, 0};
  forPoints([&](const Vec3& q) {
    for (int a = 0; a < 3; ++a) half.at(a) = std::max(half[a], std::fabs(dot(axes[size_t(a)], q - origin_ - centre)));
  });
  const double widen =
      0x1p-40 * (half.x + half.y + half.z + std::fabs(centre.x) + std::fabs(centre.y) + std::fabs(centre.z));
  for (int a = 0; a < 3; ++a) box.half[a] = floatAbove(half[a] + widen);
  return box;
}

// A leaf's float rows (WideLeaf). Each triangle's allowance: the double bound's own (slack |p - a|_1 + slackAt0,
// with |p - a|_1 at most |q|_1 + |a - origin|_1) plus kRelative of the magnitudes the float rows are computed from.
NearestPrimitive::WideLeaf NearestPrimitive::makeLeaf(const BinaryNode& node) const {
  WideLeaf leaf{};
  leaf.first = node.first;
  leaf.count = node.count;
  const auto l1 = [](const Vec3& v) { return std::fabs(v.x) + std::fabs(v.y) + std::fabs(v.z); };
  for (uint32_t lane = 0; lane < node.count; ++lane) {
    const uint32_t slot = node.first + lane;
    if (ids_[slot] >= triangleCount_ || !bounds_[slot].usable) continue;  // zero rows: never pruned
    const Triangle& t = triangles_[slot];
    const TriangleLowerBound& b = bounds_[slot];
    double magnitude = 0;
    for (const Vec3& v : t.v) magnitude = std::max(magnitude, l1(v - origin_));
    for (int a = 0; a < 3; ++a) leaf.n[a][lane] = float(b.normal[a]);
    leaf.w[lane] = float(dot(b.normal, t.v[0] - origin_));
    for (int e = 0; e < 3; ++e) {
      for (int a = 0; a < 3; ++a) leaf.e[e][a][lane] = float(b.edgeNormals[e][a]);
      leaf.ew[e][lane] = float(dot(b.edgeNormals[e], t.v[e] - origin_));
      // Corner e lies on edges e and e + 2 (e - 1): the bisector of their outward normals is a positive sum of the
      // two, so the triangle lies inside its half-plane through the corner too. Where the two normals nearly
      // cancel (a needle's tip) its direction is ill-conditioned: a zero row.
      const Vec3 bisector = b.edgeNormals[e] + b.edgeNormals[(e + 2) % 3];
      if (!(length(bisector) > 0.25)) continue;
      const Vec3 m = normalize(bisector);
      for (int a = 0; a < 3; ++a) leaf.e[3 + e][a][lane] = float(m[a]);
      leaf.ew[3 + e][lane] = float(dot(m, t.v[e] - origin_));
    }
    const double k1 = b.slack + double(kRelative);
    leaf.k1[lane] = floatAbove(k1);
    leaf.k0[lane] = floatAbove(b.slackAt0 + k1 * magnitude * (1 + 0x1p-20) + double(kAbsolute));
  }
  return leaf;
}

// The squared distance from p to the primitive in `slot`, or infinity when a triangle's plane alone is farther
// than bound2 (squaredDistanceToTriangleWithin).
double NearestPrimitive::squaredDistanceTo(uint32_t slot, const Vec3& p, double bound2) const {
  const uint32_t id = ids_[slot];
  if (id < triangleCount_) return squaredDistanceToTriangleWithin(triangles_[slot], bounds_[slot], p, bound2);
  const Vec3 d = p - closestPointOnEllipsoid(shapes_[id - triangleCount_], p);
  return dot(d, d);
}

// The seed's exact distance is the first bound, tight when the seed is the answer or nearly so, so that the search
// opens few nodes. Ties still go to the lowest id: the seed's equals are visited and win by id.
NearestHit NearestPrimitive::searchFrom(const Vec3& p, int64_t seed, const WideNode* first, size_t firstCount) const {
  if (seed < 0 || uint64_t(seed) >= ids_.size()) return nearest(p);
  const uint32_t slot = slotOf_[size_t(seed)];
  NearestHit best{squaredDistanceTo(slot, p, INFINITY), seed};
  search(p, first, firstCount, best, slot);
  return best;
}

NearestHit NearestPrimitive::nearestFrom(const Vec3& p, int64_t seed) const {
  return searchFrom(p, seed, wide_.data(), 1);
}

NearestHit NearestPrimitive::nearestFrom(const Vec3& p, int64_t seed, const Frontier& frontier) const {
  return searchFrom(p, seed, frontier.nodes_.data(), frontier.nodes_.size());
}

NearestHit NearestPrimitive::nearest(const Vec3& p, double bound2) const {
  NearestHit best;
  best.squaredDistance = bound2;
  if (!wide_.empty()) search(p, wide_.data(), 1, best);
  if (best.primitive < 0) best.squaredDistance = INFINITY;
  return best;
}

namespace {

// Float lower bounds of the squared distances from q (relative to the tree's origin) to a node's four children's
// boxes, each lowered by the rounding allowance (the constants above) below the exact distance of every primitive
// it holds.
template <typename Node>
__m128 childBounds(const Node& node, __m128 qx, __m128 qy, __m128 qz, __m128 qn) {
  const __m128 zero = _mm_setzero_ps();
  const __m128 dx = _mm_sub_ps(qx, _mm_load_ps(node.centre[0])), dy = _mm_sub_ps(qy, _mm_load_ps(node.centre[1])),
               dz = _mm_sub_ps(qz, _mm_load_ps(node.centre[2]));
  const __m128 allowance = _mm_add_ps(_mm_mul_ps(_mm_add_ps(qn, _mm_load_ps(node.magnitude)), _mm_set1_ps(kRelative)),
                                      _mm_set1_ps(kAbsolute));
  const auto outside = [&](int a) {
    const __m128 u = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(_mm_load_ps(node.axis[a][0]), dx), _mm_mul_ps(_mm_load_ps(node.axis[a][1]), dy)),
        _mm_mul_ps(_mm_load_ps(node.axis[a][2]), dz));
    const __m128 e = _mm_sub_ps(_mm_max_ps(u, _mm_sub_ps(zero, u)), _mm_add_ps(_mm_load_ps(node.half[a]), allowance));
    return _mm_max_ps(e, zero);
  };
  const __m128 ex = outside(0), ey = outside(1), ez = outside(2);
  return _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ex), _mm_mul_ps(ey, ey)), _mm_mul_ps(ez, ez)),
                    _mm_set1_ps(kShrink));
}

// A point relative to the tree's origin in float, and whether its float bounds may prune (within kFloatReach).
struct FloatQuery {
  bool prune;
  float q[3] = {0, 0, 0};  // without pruning the bounds are computed at the origin and never compared
  float norm = 0;
  FloatQuery(const Vec3& p, const Vec3& origin) {
    const Vec3 d = p - origin;
    prune = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) <= kFloatReach;
    if (prune)
      for (int a = 0; a < 3; ++a) q[a] = float(d[a]);
    norm = std::fabs(q[0]) + std::fabs(q[1]) + std::fabs(q[2]);
  }
};

}  // namespace

// The leaf's triangles' float lower bounds, four at once; the survivors get the double route (which may still prune
// with the best as it is by then), as the double search gave it to every triangle it reached.
void NearestPrimitive::visitLeaf(const WideLeaf& leaf, const Vec3& p, const float (&q)[3], float qNorm, bool prune,
                                 float bestUp, uint32_t known, NearestHit& best) const {
  const __m128 qx = _mm_set1_ps(q[0]), qy = _mm_set1_ps(q[1]), qz = _mm_set1_ps(q[2]), zero = _mm_setzero_ps();
  const auto row = [&](const float(&v)[3][4], const float* w) {
    const __m128 d = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(v[0]), qx), _mm_mul_ps(_mm_load_ps(v[1]), qy)),
                                _mm_mul_ps(_mm_load_ps(v[2]), qz));
    return _mm_sub_ps(d, _mm_load_ps(w));
  };
  const __m128 plane = row(leaf.n, leaf.w);
  const __m128 h = _mm_max_ps(plane, _mm_sub_ps(zero, plane));
  __m128 s = row(leaf.e[0], leaf.ew[0]);
  for (int e = 1; e < 6; ++e) s = _mm_max_ps(s, row(leaf.e[e], leaf.ew[e]));
  const __m128 allowance = _mm_add_ps(_mm_mul_ps(_mm_load_ps(leaf.k1), _mm_set1_ps(qNorm)), _mm_load_ps(leaf.k0));
  const __m128 hl = _mm_max_ps(_mm_sub_ps(h, allowance), zero), sl = _mm_max_ps(_mm_sub_ps(s, allowance), zero);
  const __m128 lb2 = _mm_add_ps(_mm_mul_ps(hl, hl), _mm_mul_ps(sl, sl));
  unsigned open = unsigned(_mm_movemask_ps(_mm_cmple_ps(lb2, _mm_set1_ps(bestUp)))) & ((1u << leaf.count) - 1);
  // The seed's distance is in `best` already: computed again it would equal it (a tie with its own id) or, once a
  // nearer primitive has replaced it, lose; either way nothing changes.
  if (known - leaf.first < leaf.count) open &= ~(1u << (known - leaf.first));
  if (open == 0) return;
  // The survivors nearest bound first, each bound checked again against the best so far: the first exact distance
  // then prunes most of the rest. The answer does not depend on the order (ties go to the lowest id in any order).
  alignas(16) float bound[4];
  _mm_store_ps(bound, lb2);
  int order[4];
  int count = 0;
  for (; open != 0; open &= open - 1) {
    const int lane = __builtin_ctz(open);
    int i = count++;
    for (; i > 0 && bound[order[i - 1]] > bound[lane]; --i) order[i] = order[i - 1];
    order[i] = lane;
  }
  for (int k = 0; k < count; ++k) {
    if (k > 0 && bound[order[k]] > bestUp) break;  // the rest are farther still
    const uint32_t slot = leaf.first + uint32_t(order[k]);
    const double d2 = squaredDistanceTo(slot, p, best.squaredDistance);
    const int64_t id = ids_[slot];
    if (d2 < best.squaredDistance || (d2 == best.squaredDistance && (best.primitive < 0 || id < best.primitive))) {
      best.squaredDistance = d2;
      best.primitive = id;
      if (prune) bestUp = pruneAbove(d2);
    }
  }
}

// Lowers `best` to the nearest primitive within it (ties to the lowest id): every child whose float box bound is
// no farther than the best so far (pruneAbove) is visited, nearer children first. The search starts from the
// children of `first` (the root, or a region's frontier).
void NearestPrimitive::search(const Vec3& p, const WideNode* first, size_t firstCount, NearestHit& best,
                              uint32_t known) const {
  const FloatQuery fq(p, origin_);
  const bool prune = fq.prune;
  const __m128 qx = _mm_set1_ps(fq.q[0]), qy = _mm_set1_ps(fq.q[1]), qz = _mm_set1_ps(fq.q[2]);
  const __m128 qn = _mm_set1_ps(fq.norm);
  float bestUp = prune ? pruneAbove(best.squaredDistance) : INFINITY;
  // The first nodes push at most kMaxFrontier entries; each level after pushes at most three more than it pops, and
  // the depth is at most 32.
  struct Waiting {
    int32_t node;
    float d2;
  };
  std::array<Waiting, kMaxFrontier + 3 * 32 + 4> stack;
  size_t top = 0;
  // Pushes the node's open children so that the nearest of those since `base` is popped first.
  const auto open = [&](const WideNode& node, size_t base) {
    alignas(16) float bound[4];
    const __m128 lb2 = childBounds(node, qx, qy, qz, qn);
    _mm_store_ps(bound, lb2);
    unsigned lanes = unsigned(_mm_movemask_ps(_mm_cmple_ps(lb2, _mm_set1_ps(bestUp)))) & ((1u << node.count) - 1);
    for (; lanes != 0; lanes &= lanes - 1) {
      const int lane = __builtin_ctz(lanes);
      size_t i = top++;
      for (; i > base && stack[i - 1].d2 < bound[lane]; --i) stack[i] = stack[i - 1];
      stack[i] = {node.child[lane], bound[lane]};
    }
  };
  for (size_t i = 0; i < firstCount; ++i) open(first[i], 0);
  while (top > 0) {
    const Waiting next = stack[--top];
    if (next.d2 > bestUp) continue;
    if (next.node >= 0) {
      open(wide_[size_t(next.node)], top);
      continue;
    }
    visitLeaf(leaves_[size_t(~next.node)], p, fq.q, fq.norm, prune, bestUp, known, best);
    if (prune) bestUp = pruneAbove(best.squaredDistance);
  }
}

// Region pruning, from the search's own certificate: a child's float bound b at the region's centre lies below the
// computed (so, within a relative 2^-50, the real) distance from the centre of every primitive it holds. If
// sqrt(b) exceeds keep = (upper + radius) (1 + 2^-28) + 2^-60, each such primitive is farther than
// upper (1 + 2^-28) from every point of the region, and so, with `upper` at least the real distance from that point
// to some primitive, computed farther than it too: the point's search would have found it farther than its best and
// never counted it, equal or nearer. The 2^-60 keeps those distances' squares clear of underflow.
void NearestPrimitive::gather(const Vec3& centre, double radius, double upper, size_t maxEntries,
                              Frontier& frontier) const {
  frontier.nodes_.clear();
  if (wide_.empty()) return;
  const FloatQuery fq(centre, origin_);
  const double keep = (upper + radius) * (1 + 0x1p-28) + 0x1p-60;
  if (!fq.prune || !(keep * keep < double(std::numeric_limits<float>::max()))) {
    frontier.nodes_.push_back(wide_[0]);
    return;
  }
  const __m128 keep2 = _mm_set1_ps(floatAbove(keep * keep * (1 + 0x1p-26)));
  const __m128 qx = _mm_set1_ps(fq.q[0]), qy = _mm_set1_ps(fq.q[1]), qz = _mm_set1_ps(fq.q[2]);
  const __m128 qn = _mm_set1_ps(fq.norm);
  struct Entry {
    const WideNode* node;  // the lane's parent
    int lane;
    float size;  // the sum of its half extents
  };
  std::array<Entry, kMaxFrontier + 4> entries;
  const auto keptChildren = [&](const WideNode& node, std::array<Entry, 4>& out) {
    const unsigned lanes =
        unsigned(_mm_movemask_ps(_mm_cmple_ps(childBounds(node, qx, qy, qz, qn), keep2))) & ((1u << node.count) - 1);
    size_t n = 0;
    for (unsigned l = lanes; l != 0; l &= l - 1) {
      const int lane = __builtin_ctz(l);
      out[n++] = {&node, lane, node.half[0][lane] + node.half[1][lane] + node.half[2][lane]};
    }
    return n;
  };
  std::array<Entry, 4> children;
  size_t count = keptChildren(wide_[0], children);
  std::copy_n(children.begin(), count, entries.begin());
  maxEntries = std::clamp<size_t>(maxEntries, 4, kMaxFrontier);
  // The largest inner child replaced by its kept children while they fit.
  for (;;) {
    size_t widest = count;
    for (size_t e = 0; e < count; ++e)
      if (entries[e].node->child[entries[e].lane] >= 0 && (widest == count || entries[e].size > entries[widest].size))
        widest = e;
    if (widest == count) break;
    const size_t n = keptChildren(wide_[size_t(entries[widest].node->child[entries[widest].lane])], children);
    if (count - 1 + n > maxEntries) break;
    entries[widest] = entries[--count];
    std::copy_n(children.begin(), n, entries.begin() + ptrdiff_t(count));
    count += n;
  }
  // Packed four to a node, lane by lane.
  for (size_t e = 0; e < count; ++e) {
    if (e % 4 == 0) frontier.nodes_.push_back(WideNode{});  // unused lanes zero, masked out
    WideNode& packed = frontier.nodes_.back();
    const WideNode& from = *entries[e].node;
    const int lane = entries[e].lane, to = int(packed.count++);
    for (int a = 0; a < 3; ++a) {
      packed.centre[a][to] = from.centre[a][lane];
      packed.half[a][to] = from.half[a][lane];
      for (int i = 0; i < 3; ++i) packed.axis[a][i][to] = from.axis[a][i][lane];
    }
    packed.magnitude[to] = from.magnitude[lane];
    packed.child[to] = from.child[lane];
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
