#include "vox/voxelize/bricks.h"

#include "vox/core/error.h"

namespace vox {

std::vector<std::vector<uint32_t>> brickCandidates(const Scene& scene, const Grid& plan,
                                                   const std::array<uint32_t, 3>& bricks, uint64_t memoryLimitBytes) {
  checkBrickCounts(plan.dims, bricks);
  const size_t nTri = scene.triangles.size(), nBounded = scene.boundedCount();
  // The bricks a primitive's cell range meets, per axis; empty when the range misses the grid.
  auto brickRange = [&](size_t id, std::array<uint32_t, 3>& lo, std::array<uint32_t, 3>& hi) {
    const Box box = id < nTri ? triangleBounds(scene.triangles[id]) : sphereBounds(scene.spheres[id - nTri]);
    for (int a = 0; a < 3; ++a) {
      const auto [f, l] = cellRange(plan.bounds, plan.dims, a, box.lo[a], box.hi[a]);
      if (f > l) return false;
      lo[a] = brickOfCell(uint64_t(f), plan.dims[a], bricks[a]);
      hi[a] = brickOfCell(uint64_t(l), plan.dims[a], bricks[a]);
    }
    return true;
  };
  auto forEachBrick = [&](auto&& visit) {
    std::array<uint32_t, 3> lo, hi;
    for (size_t id = 0; id < nBounded; ++id) {
      if (!brickRange(id, lo, hi)) continue;
      for (uint32_t z = lo[2]; z <= hi[2]; ++z)
        for (uint32_t y = lo[1]; y <= hi[1]; ++y)
          for (uint32_t x = lo[0]; x <= hi[0]; ++x) visit(brickNumber(bricks, {x, y, z}), uint32_t(id));
    }
  };
  // Counted first, so that a huge primitive over many small bricks is refused before the lists are made.
  const uint64_t brickCount = uint64_t(bricks[0]) * bricks[1] * bricks[2];
  std::vector<uint64_t> counts(brickCount, 0);
  forEachBrick([&](uint64_t b, uint32_t) { ++counts[b]; });
  double bytes = double(brickCount) * sizeof(std::vector<uint32_t>);
  for (uint64_t c : counts) bytes += 4.0 * double(c);
  if (bytes > double(memoryLimitBytes))
    fail<LimitError>("the primitive lists of ", brickCount, " bricks need ", uint64_t(bytes / (1 << 20)),
                     " MiB, more than the ", memoryLimitBytes >> 20, " MiB allowed");
  std::vector<std::vector<uint32_t>> lists(brickCount);
  for (uint64_t b = 0; b < brickCount; ++b) lists[b].reserve(counts[b]);
  forEachBrick([&](uint64_t b, uint32_t id) { lists[b].push_back(id); });
  return lists;
}

}  // namespace vox
