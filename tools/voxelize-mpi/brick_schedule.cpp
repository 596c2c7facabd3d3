#include "brick_schedule.h"

#include <algorithm>

#include "vox/voxelize/bricks.h"

namespace vox::mpi {

BrickSchedule planBricks(const Scene& scene, const VoxelizeOptions& options, const std::array<uint32_t, 3>& bricks) {
  BrickSchedule s;
  s.plan = planGrid(scene, options);
  checkBrickCounts(s.plan.dims, bricks);
  if (options.bounds) s.plan.outsidePrims = primitivesOutside(scene, s.plan);
  s.candidates = brickCandidates(scene, s.plan, bricks, options.memoryLimitBytes);
  return s;
}

std::vector<uint64_t> brickOrder(const std::vector<std::vector<uint32_t>>& candidates) {
  std::vector<uint64_t> order;
  for (uint64_t b = 0; b < candidates.size(); ++b)
    if (!candidates[b].empty()) order.push_back(b);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint64_t a, uint64_t b) { return candidates[a].size() > candidates[b].size(); });
  return order;
}

}  // namespace vox::mpi
