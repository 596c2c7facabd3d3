// vox-voxelize-mpi's brick schedule (tools/voxelize-mpi/brick_schedule.cpp): the plan every rank computes alike,
// and the order bricks are handed out in. No mpirun needed.
#include "voxelize-mpi/brick_schedule.h"

#include <gtest/gtest.h>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/voxelize/bricks.h"

namespace vox::mpi {
namespace {

TEST(VoxelizeMpiBrickSchedule, DensestBricksFirstEmptyOnesLeftOut) {
  const std::vector<std::vector<uint32_t>> candidates{{1, 2}, {}, {3, 4, 5}, {6}, {7, 8}, {}};
  EXPECT_EQ(brickOrder(candidates), (std::vector<uint64_t>{2, 0, 4, 3}));  // ties: lower number first
  EXPECT_TRUE(brickOrder({{}, {}}).empty());
}

TEST(VoxelizeMpiBrickSchedule, PlanIsVoxelizeBricksPlan) {
  const Scene scene = testing::randomScene(3, 60, 3, -1, 2);
  VoxelizeOptions vo;
  vo.resolution = 12;
  const std::array<uint32_t, 3> bricks{3, 2, 2};
  const BrickSchedule s = planBricks(scene, vo, bricks);
  const Grid plan = planGrid(scene, vo);
  EXPECT_EQ(s.plan.dims, plan.dims);
  EXPECT_TRUE(s.plan.outsidePrims.empty());
  EXPECT_EQ(s.candidates, brickCandidates(scene, plan, bricks, vo.memoryLimitBytes));
  EXPECT_TRUE(s.order.empty());
  uint64_t withCandidates = 0;
  for (const auto& c : s.candidates) withCandidates += !c.empty();
  EXPECT_EQ(brickOrder(s.candidates).size(), withCandidates);
}

TEST(VoxelizeMpiBrickSchedule, UserBoundsAndBadBrickCounts) {
  const Scene scene = testing::randomScene(4, 30, 0, -1, 2);
  VoxelizeOptions vo;
  vo.dims = std::array<uint32_t, 3>{4, 4, 4};
  vo.bounds = Box{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  const BrickSchedule s = planBricks(scene, vo, {2, 2, 2});
  Grid plan = planGrid(scene, vo);
  EXPECT_EQ(s.plan.outsidePrims, primitivesOutside(scene, plan));
  EXPECT_FALSE(s.plan.outsidePrims.empty());
  EXPECT_THROW(planBricks(scene, vo, {5, 1, 1}), UsageError);  // more bricks than cells on x
}

}  // namespace
}  // namespace vox::mpi
