// vox-voxelize-mpi's rank protocol (tools/voxelize-mpi/rank_protocol.cpp): what a rank reports survives packing, and
// rank 0 decides from every report as the tool must (first failing rank, the manifest's entries, a batch's errors in
// list order, the --stats lines). No mpirun needed.
#include "voxelize-mpi/rank_protocol.h"

#include <gtest/gtest.h>

#include "vox/core/tool.h"

namespace vox::mpi {
namespace {

BrickEntry entry(std::array<uint32_t, 3> index, uint64_t occupied) {
  BrickEntry e;
  e.index = index;
  e.file = "s.bricks/g0/b_" + std::to_string(index[0]) + ".vgrid";
  e.fileSize = 100 + occupied;
  e.fileChecksum = 0xabcdef0123456789ull ^ occupied;
  e.occupied = occupied;
  e.references = 2 * occupied;
  e.solid = occupied / 2;
  return e;
}

bool sameEntry(const BrickEntry& a, const BrickEntry& b) {
  return a.index == b.index && a.file == b.file && a.fileSize == b.fileSize && a.fileChecksum == b.fileChecksum &&
         a.occupied == b.occupied && a.references == b.references && a.solid == b.solid;
}

TEST(VoxelizeMpiRankProtocol, OutcomeSurvivesPacking) {
  Outcome o;
  o.code = kExitBadInput;
  o.message = std::string("bad\0scene\n", 10);
  o.seconds = 1.25;
  o.peakMb = 321.5;
  o.items = 7;
  o.bricks = {entry({1, 2, 3}, 5), entry({0, 0, 0}, 0)};
  o.scenes = {{4, 0, ""}, {9, kExitCannotWrite, "out/x.vgrid: cannot write"}};
  const Outcome back = unpackOutcome(packOutcome(o));
  EXPECT_EQ(back.code, o.code);
  EXPECT_EQ(back.message, o.message);
  EXPECT_EQ(back.seconds, o.seconds);
  EXPECT_EQ(back.peakMb, o.peakMb);
  EXPECT_EQ(back.items, o.items);
  ASSERT_EQ(back.bricks.size(), 2u);
  for (size_t i = 0; i < 2; ++i) EXPECT_TRUE(sameEntry(back.bricks[i], o.bricks[i])) << i;
  EXPECT_EQ(back.scenes, o.scenes);
  const Outcome empty = unpackOutcome(packOutcome(Outcome{}));
  EXPECT_EQ(empty.code, 0);
  EXPECT_TRUE(empty.bricks.empty() && empty.scenes.empty());
}

Outcome failed(int32_t code, const std::string& message) {
  Outcome o;
  o.code = code;
  o.message = message;
  return o;
}

TEST(VoxelizeMpiRankProtocol, TheFirstFailingRankFailsTheSet) {
  std::vector<Outcome> all(3);
  std::string message;
  EXPECT_EQ(setFailure(all, message), kExitOk);
  all[1] = failed(kExitCannotWrite, "b_1.vgrid: disk full");
  all[2] = failed(kExitBadInput, "scene.obj: line 3: bad");
  EXPECT_EQ(setFailure(all, message), kExitCannotWrite);
  EXPECT_EQ(message, "rank 1: b_1.vgrid: disk full");
  const std::vector<Outcome> one{failed(kExitBadInput, "scene.obj: line 3: bad")};
  EXPECT_EQ(setFailure(one, message), kExitBadInput);
  EXPECT_EQ(message, "scene.obj: line 3: bad");  // one rank: no rank named
}

TEST(VoxelizeMpiRankProtocol, ManifestEntriesMergedAscendingWithoutEmptyBricks) {
  GridSetManifest set;
  set.bricks = {2, 2, 2};
  std::vector<Outcome> all(2);
  all[0].bricks = {entry({1, 1, 1}, 3), entry({0, 0, 0}, 0), entry({1, 0, 0}, 2)};
  all[1].bricks = {entry({0, 1, 0}, 4), entry({0, 0, 1}, 1)};
  const GridSetManifest m = mergeBrickEntries(set, all);
  ASSERT_EQ(m.entries.size(), 4u);
  const std::array<uint32_t, 3> want[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(m.entries[i].index, want[i]) << i;
  EXPECT_EQ(m.bricks, set.bricks);
}

TEST(VoxelizeMpiRankProtocol, BatchErrorsInListOrderAndTheLargestCode) {
  std::vector<Outcome> all(2);
  all[0].scenes = {{3, kExitCannotWrite, "out/d.vgrid: cannot write"}, {0, kExitOk, ""}};
  all[1].scenes = {{2, kExitOk, ""}, {1, kExitBadInput, "b.obj: line 1: bad"}};
  const BatchSummary s = summarizeBatch(all);
  EXPECT_EQ(s.code, kExitCannotWrite);
  EXPECT_EQ(s.errors, (std::vector<std::string>{"b.obj: line 1: bad", "out/d.vgrid: cannot write"}));
  const BatchSummary ok = summarizeBatch({Outcome{}});
  EXPECT_EQ(ok.code, kExitOk);
  EXPECT_TRUE(ok.errors.empty());
}

TEST(VoxelizeMpiRankProtocol, StatsLines) {
  std::vector<Outcome> all(2);
  all[0].items = 3, all[0].seconds = 1.5, all[0].peakMb = 10.3;
  all[1].items = 4, all[1].seconds = 0.25, all[1].peakMb = 20;
  EXPECT_EQ(rankStatsText(all, 2.5),
            "rank_0: items 3 work_seconds 1.500 peak_memory_mb 10.3\n"
            "rank_1: items 4 work_seconds 0.250 peak_memory_mb 20.0\n"
            "ranks: 2\ntotal_seconds: 2.500000\nmax_peak_memory_mb: 20.0\n");
  EXPECT_GT(peakMemoryMb(), 0);
}

}  // namespace
}  // namespace vox::mpi
