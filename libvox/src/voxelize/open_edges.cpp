#include "vox/voxelize/open_edges.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>
#include <tuple>
#include <vector>

namespace vox {

uint64_t countOpenEdges(std::span<const Triangle> triangles) {
  const size_t corners = triangles.size() * 3;
  auto at = [&](uint64_t c) -> const Vec3& { return triangles[c / 3].v[c % 3]; };
  // Weld: sort corners by position; equal positions get one id. -0.0 and 0.0 compare equal, as they should.
  std::vector<uint32_t> order(corners);
  std::iota(order.begin(), order.end(), 0u);
  tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const Vec3 &p = at(a), &q = at(b);
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
  });
  std::vector<uint32_t> id(corners);
  uint32_t next = 0;
  for (size_t c = 0; c < corners; ++c) {
    if (c > 0) {
      const Vec3 &p = at(order[c - 1]), &q = at(order[c]);
      if (p.x != q.x || p.y != q.y || p.z != q.z) ++next;
    }
    id[order[c]] = next;
  }
  order = {};
  std::vector<uint64_t> edges;
  edges.reserve(corners);
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = id[t * 3 + e], b = id[t * 3 + (e + 1) % 3];
      if (a != b) edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  tbb::parallel_sort(edges.begin(), edges.end());
  uint64_t open = 0;
  for (size_t e = 0; e < edges.size();) {
    size_t f = e;
    while (f < edges.size() && edges[f] == edges[e]) ++f;
    open += (f - e) & 1;
    e = f;
  }
  return open;
}

}  // namespace vox
