#include "vox/voxelize/winding_number.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace vox {

namespace {

constexpr double kInv4Pi = 1.0 / (4.0 * std::numbers::pi);
constexpr uint32_t kLeafSize = 8;

struct BuildInput {
  std::vector<std::array<Vec3, 3>> corners;
  std::vector<Vec3> centroid;
  std::vector<Vec3> areaNormal;  // (b - a) x (c - a) / 2: area times unit normal
};

// Fills the expansion of node `n` over triangles [first, first + count) of `in` (already in tree order).
void summarize(WindingTree::Node& n, const BuildInput& in) {
  double area = 0;
  Vec3 weighted{0, 0, 0}, lo = in.corners[n.first][0], hi = lo;
  for (uint32_t t = n.first; t < n.first + n.count; ++t) {
    const double a = length(in.areaNormal[t]);
    area += a;
    weighted = weighted + in.centroid[t] * a;
    n.normalSum = n.normalSum + in.areaNormal[t];
    for (const Vec3& v : in.corners[t]) lo = minVec(lo, v), hi = maxVec(hi, v);
  }
  // Degenerate triangles have no area: fall back to the box centre, any point works for a zero expansion.
  n.center = area > 0 ? weighted / area : (lo + hi) * 0.5;
  for (uint32_t t = n.first; t < n.first + n.count; ++t) {
    const Vec3 d = in.centroid[t] - n.center;
    const Vec3& an = in.areaNormal[t];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) n.moment[r * 3 + c] += an[r] * d[c];
    for (const Vec3& v : in.corners[t]) n.radius = std::max(n.radius, length(v - n.center));
  }
}

// Nodes of the subtree over `count` triangles: known before building, so that subtrees can be built in parallel
// into their own index ranges of the depth-first order.
uint32_t subtreeNodes(uint32_t count) {
  return count > kLeafSize ? 1 + subtreeNodes(count / 2) + subtreeNodes(count - count / 2) : 1;
}

// Median split on the longest axis of the centroids, depth first, so that a subtree is a contiguous node range.
void buildNode(WindingTree& tree, const BuildInput& in, std::vector<uint32_t>& order, uint32_t first, uint32_t count,
               uint32_t index) {
  WindingTree::Node& n = tree.nodes[index];
  n.first = first;
  n.count = count;
  n.skip = index + subtreeNodes(count);
  if (count <= kLeafSize) return;
  Vec3 lo = in.centroid[order[first]], hi = lo;
  for (uint32_t t = first; t < first + count; ++t) {
    lo = minVec(lo, in.centroid[order[t]]);
    hi = maxVec(hi, in.centroid[order[t]]);
  }
  const Vec3 ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const uint32_t half = count / 2;
  std::nth_element(order.begin() + first, order.begin() + first + half, order.begin() + first + count,
                   [&](uint32_t a, uint32_t b) { return in.centroid[a][axis] < in.centroid[b][axis]; });
  auto left = [&] { buildNode(tree, in, order, first, half, index + 1); };
  auto right = [&] { buildNode(tree, in, order, first + half, count - half, index + 1 + subtreeNodes(half)); };
  if (count < 4096)
    left(), right();
  else
    tbb::parallel_invoke(left, right);
}

}  // namespace

double triangleWindingNumber(const Vec3& a0, const Vec3& b0, const Vec3& c0, const Vec3& q) {
  const Vec3 a = a0 - q, b = b0 - q, c = c0 - q;
  const double la = length(a), lb = length(b), lc = length(c);
  double num = dot(a, cross(b, c));
  // Near the triangle's plane the rounded triple product can take the wrong sign, and over the triangle's interior
  // that flips its term from +1/2 to -1/2: a point a hair inside a closed surface would count as outside. There the
  // sign comes from CGAL's exact orientation predicate (filtered: exact for double input); num's magnitude only
  // matters far from the jump. The bound is loose on purpose: rounding errs by a few ulps of la lb lc.
  if (std::fabs(num) <= 1e-12 * la * lb * lc) {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    const auto point = [](const Vec3& v) { return K::Point_3(v.x, v.y, v.z); };
    // det(a0 - q, b0 - q, c0 - q) = -det(b0 - a0, c0 - a0, q - a0), CGAL's orientation(a0, b0, c0, q).
    const int exact = -int(CGAL::orientation(point(a0), point(b0), point(c0), point(q)));
    if (exact == 0) return 0;  // q exactly in the triangle's plane (on it: on the surface) or degenerate
    num = std::copysign(std::max(std::fabs(num), 1e-300), double(exact));
  }
  if (num == 0) return 0;
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2 * std::atan2(num, den) * kInv4Pi;
}

double windingNumberExact(std::span<const Triangle> triangles, const Vec3& q) {
  double w = 0;
  for (const Triangle& t : triangles) w += triangleWindingNumber(t.v[0], t.v[1], t.v[2], q);
  return w;
}

WindingTree buildWindingTree(std::span<const Triangle> triangles) {
  WindingTree tree;
  if (triangles.empty()) return tree;
  const uint32_t n = uint32_t(triangles.size());
  BuildInput in;
  in.centroid.resize(n);
  for (uint32_t t = 0; t < n; ++t) in.centroid[t] = (triangles[t].v[0] + triangles[t].v[1] + triangles[t].v[2]) / 3.0;
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  tree.nodes.resize(subtreeNodes(n));
  buildNode(tree, in, order, 0, n, 0);
  // Triangles in tree order, then each node's expansion over its range.
  in.corners.resize(n);
  in.areaNormal.resize(n);
  std::vector<Vec3> centroid(n);
  for (uint32_t t = 0; t < n; ++t) {
    const Triangle& tri = triangles[order[t]];
    in.corners[t] = tri.v;
    in.areaNormal[t] = cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]) * 0.5;
    centroid[t] = in.centroid[order[t]];
  }
  in.centroid = std::move(centroid);
  tbb::parallel_for(size_t(0), tree.nodes.size(), [&](size_t i) { summarize(tree.nodes[i], in); });
  tree.corners = std::move(in.corners);
  return tree;
}

// The far field of a node is the double-layer potential of its triangles, n.(x - q)/|x - q|^3 integrated over the
// surface; Taylor-expanded around the node's centre r = center - q it is
//   normalSum . r / |r|^3  +  sum_ij moment_ij (delta_ij / |r|^3 - 3 r_i r_j / |r|^5)     (Barill et al. eq. 8).
double windingNumber(const WindingTree& tree, const Vec3& q, double beta) {
  double w = 0;
  uint32_t i = 0;
  const uint32_t end = uint32_t(tree.nodes.size());
  while (i < end) {
    const WindingTree::Node& n = tree.nodes[i];
    const Vec3 r = n.center - q;
    const double d2 = dot(r, r);
    if (d2 > beta * beta * n.radius * n.radius) {
      const double inv = 1 / std::sqrt(d2), inv3 = inv * inv * inv, inv5 = inv3 * inv * inv;
      double order2 = (n.moment[0] + n.moment[4] + n.moment[8]) * inv3;
      double rmr = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) rmr += r[a] * n.moment[a * 3 + b] * r[b];
      order2 -= 3 * rmr * inv5;
      w += (dot(n.normalSum, r) * inv3 + order2) * kInv4Pi;
      i = n.skip;
    } else if (n.skip == i + 1) {  // a leaf too close for its expansion: its triangles exactly
      for (uint32_t t = n.first; t < n.first + n.count; ++t)
        w += triangleWindingNumber(tree.corners[t][0], tree.corners[t][1], tree.corners[t][2], q);
      i = n.skip;
    } else {
      ++i;
    }
  }
  return w;
}

double windingNumberToDecide(const WindingTree& tree, const Vec3& q, double offset, double threshold) {
  constexpr double kRefineMargin = 0.05, kRefineBeta = 8;
  const double w = windingNumber(tree, q);
  if (std::abs(std::abs(offset - w) - threshold) >= kRefineMargin) return w;
  return windingNumber(tree, q, kRefineBeta);
}

}  // namespace vox
