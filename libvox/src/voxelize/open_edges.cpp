#include "vox/voxelize/open_edges.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <numeric>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace vox {

namespace {

struct WeldedEdges {
  std::vector<uint64_t> open;  // (id a << 32 | id b), a < b: used by an odd number of triangles
  // Edges used more often in one direction than in the other: the oriented boundary. `second` is the surplus, > 0
  // when the edge is used more often from its smaller id to its larger. The same as `open` for a consistently
  // oriented mesh; also the seams where the orientation flips.
  std::vector<std::pair<uint64_t, int>> unbalanced;
  std::vector<uint32_t> cornerOfId;  // a corner (3 * triangle + vertex) at each welded id
};

// One use of an undirected edge, with its direction: +1 from the smaller id, -1 from the larger. Sorted, each edge's
// uses are adjacent and the edges in the order of (smaller id, larger id), in either form. PackedUse is one word
// (the smaller id from bit 33, the larger from bit 1, the direction in bit 0) for ids below kPackedIds: half of
// PairUse's memory, 24 bytes a triangle where the pairs took 48, the peak of --sdf's sign test at 4.4 M triangles.
constexpr uint64_t kPackedIds = uint64_t(1) << 31;
struct PackedUse {
  uint64_t word;
  PackedUse(uint64_t a, uint64_t b) : word(std::min(a, b) << 33 | std::max(a, b) << 1 | uint64_t(a > b)) {}
  uint64_t edge() const { return (word >> 33) << 32 | ((word >> 1) & 0xffffffffu); }
  int direction() const { return word & 1 ? -1 : 1; }
  bool operator<(const PackedUse& o) const { return word < o.word; }
};
struct PairUse {
  uint64_t key;
  int sign;
  PairUse(uint64_t a, uint64_t b) : key(std::min(a, b) << 32 | std::max(a, b)), sign(a < b ? 1 : -1) {}
  uint64_t edge() const { return key; }
  int direction() const { return sign; }
  bool operator<(const PairUse& o) const { return std::tie(key, sign) < std::tie(o.key, o.sign); }
};

// The edges of the triangles (`id`: the welded id of each corner) used an odd number of times, and those used more
// often in one direction than in the other, into `out`.
template <typename Use>
void tallyEdges(size_t triangles, std::vector<uint32_t>& id, WeldedEdges& out) {
  std::vector<Use> uses;
  uses.reserve(3 * triangles);
  for (size_t t = 0; t < triangles; ++t)
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = id[t * 3 + e], b = id[t * 3 + (e + 1) % 3];
      if (a != b) uses.emplace_back(a, b);
    }
  id = {};
  tbb::parallel_sort(uses.begin(), uses.end());
  for (size_t e = 0; e < uses.size();) {
    size_t f = e;
    int net = 0;
    for (; f < uses.size() && uses[f].edge() == uses[e].edge(); ++f) net += uses[f].direction();
    if ((f - e) & 1) out.open.push_back(uses[e].edge());
    if (net != 0) out.unbalanced.push_back({uses[e].edge(), net});
    e = f;
  }
}

WeldedEdges findOpenEdges(std::span<const Triangle> triangles) {
  const size_t corners = triangles.size() * 3;
  auto at = [&](uint64_t c) -> const Vec3& { return triangles[c / 3].v[c % 3]; };
  // Weld: sort corners by position; equal positions get one id. -0.0 and 0.0 compare equal, as they should.
  std::vector<uint32_t> order(corners);
  std::iota(order.begin(), order.end(), 0u);
  tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const Vec3 &p = at(a), &q = at(b);
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
  });
  WeldedEdges out;
  std::vector<uint32_t> id(corners);
  for (size_t c = 0; c < corners; ++c) {
    const bool same = c > 0 && at(order[c - 1]).x == at(order[c]).x && at(order[c - 1]).y == at(order[c]).y &&
                      at(order[c - 1]).z == at(order[c]).z;
    if (!same) out.cornerOfId.push_back(order[c]);
    id[order[c]] = uint32_t(out.cornerOfId.size() - 1);
  }
  order = {};
  if (out.cornerOfId.size() <= kPackedIds)
    tallyEdges<PackedUse>(triangles.size(), id, out);
  else
    tallyEdges<PairUse>(triangles.size(), id, out);
  return out;
}

}  // namespace

uint64_t countOpenEdges(std::span<const Triangle> triangles) { return findOpenEdges(triangles).open.size(); }

std::vector<OpenBoundary> openBoundaries(std::span<const Triangle> triangles, uint64_t* openEdges, size_t capLimit) {
  const WeldedEdges w = findOpenEdges(triangles);
  if (openEdges) *openEdges = w.open.size();
  auto point = [&](uint64_t id) -> const Vec3& { return triangles[w.cornerOfId[id] / 3].v[w.cornerOfId[id] % 3]; };
  // Union-find over the welded ids that boundary edges touch.
  std::unordered_map<uint64_t, uint64_t> parent;
  auto find = [&](uint64_t x) {
    auto it = parent.try_emplace(x, x).first;
    while (it->second != x) {
      x = it->second;
      it = parent.find(x);
    }
    return x;
  };
  for (const auto& [e, n] : w.unbalanced) {
    const uint64_t a = find(e >> 32), b = find(e & 0xffffffffu);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::unordered_map<uint64_t, size_t> index;
  std::vector<OpenBoundary> out;
  for (const auto& [e, n] : w.unbalanced) {
    const Vec3 &p = point(e >> 32), &q = point(e & 0xffffffffu);
    auto [it, added] = index.try_emplace(find(e >> 32), out.size());
    if (added) out.push_back({{p, p}, 0, 0, 0, {}});
    OpenBoundary& b = out[it->second];
    b.bounds.lo = minVec(minVec(b.bounds.lo, p), q);
    b.bounds.hi = maxVec(maxVec(b.bounds.hi, p), q);
    b.length += std::abs(n) * length(q - p);
    b.edges += uint64_t(std::abs(n) & 1);
  }
  const bool capped = out.size() <= capLimit;
  for (const auto& [e, n] : w.unbalanced) {
    OpenBoundary& b = out[index.at(find(e >> 32))];
    const Vec3 c = (b.bounds.lo + b.bounds.hi) * 0.5;
    // The edge is used |n| more times from `from` to `to` than back: the cap uses it |n| times from `to` to `from`.
    const Vec3 &from = point(n > 0 ? e >> 32 : e & 0xffffffffu), &to = point(n > 0 ? e & 0xffffffffu : e >> 32);
    for (int copy = 0; capped && copy < std::abs(n); ++copy) b.cap.push_back({{c, to, from}});
    b.capArea += 0.5 * std::abs(n) * length(cross(from - c, to - c));
  }
  return out;
}

double capWindingBound(std::span<const OpenBoundary> boundaries, const Box& region) {
  double sum = 0;
  for (const OpenBoundary& b : boundaries) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double gap = std::max({b.bounds.lo[a] - region.hi[a], region.lo[a] - b.bounds.hi[a], 0.0});
      d2 += gap * gap;
    }
    if (d2 == 0) return std::numeric_limits<double>::infinity();
    sum += b.capArea / (4 * std::numbers::pi * d2);
  }
  return sum;
}

}  // namespace vox
