// Writing a grid set: the scene file first, then each brick voxelized and written before the next starts (so one
// brick's cells are in memory at a time), the fill's solid runs, the manifest last (so a failure anywhere leaves no
// manifest).
#include <algorithm>
#include <filesystem>
#include <system_error>

#include "io/grid_set_header.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"

namespace vox {

namespace {

std::string brickFolderName(const std::string& setPath) {
  return std::filesystem::path(setPath).stem().string() + ".bricks";
}

std::string besideManifest(const std::string& setPath, const std::string& file) {
  return (std::filesystem::path(setPath).parent_path() / file).string();
}

}  // namespace

std::string brickFileName(const std::string& setPath, const std::array<uint32_t, 3>& index) {
  return brickFolderName(setPath) + "/b_" + std::to_string(index[0]) + "_" + std::to_string(index[1]) + "_" +
         std::to_string(index[2]) + ".vgrid";
}

std::string sceneFileName(const std::string& setPath) { return brickFolderName(setPath) + "/scene.vgrid"; }

void makeBrickFolder(const std::string& setPath) {
  const auto folder = std::filesystem::path(setPath).parent_path() / brickFolderName(setPath);
  std::error_code ec;
  // The manifest names the bricks by this folder, and readers refuse names with control bytes: refuse them before
  // writing a set no reader takes.
  if (hasControlByte(brickFolderName(setPath)))
    fail<OutputError>(quoteInput(setPath, 200), ": cannot write a grid set whose name holds control characters");
  // A device or FIFO can take a grid's bytes but not a set: its bricks would go into /dev.
  if (std::filesystem::exists(setPath, ec) && !std::filesystem::is_regular_file(setPath, ec))
    fail<OutputError>(setPath, ": cannot write: a grid set's manifest must be a regular file");
  std::filesystem::create_directory(folder, ec);
  if (ec || !std::filesystem::is_directory(folder, ec))
    fail<OutputError>(folder.string(), ": cannot create the brick folder",
                      ec ? ": " + ec.message() : std::string(": a file of that name is in the way"));
}

GridSetScene writeGridSetScene(const std::string& setPath, const Scene& scene, const Grid& plan, bool write) {
  Grid g = emptyGridLike(plan);
  g.outsidePrims = plan.outsidePrims;
  const std::string bytes = encodeGridFile(scene, g);
  GridSetScene s{sceneFileName(setPath), bytes.size(), headerChecksum(bytes)};
  if (write) writeFileAtomically(besideManifest(setPath, s.file), bytes);
  return s;
}

BrickEntry writeBrickFile(const std::string& setPath, const GridSetManifest& set, const std::array<uint32_t, 3>& index,
                          const Grid& cells) {
  BrickEntry e;
  e.index = index;
  e.file = brickFileName(setPath, index);
  e.occupied = cells.occupiedCount();
  e.references = cells.referenceCount();
  e.solid = cells.solidCount();
  const std::string bytes = encodeBrickFile(set, index, cells);
  e.fileSize = bytes.size();
  e.fileChecksum = headerChecksum(bytes);
  writeFileAtomically(besideManifest(setPath, e.file), bytes);
  return e;
}

BrickEntry writeBrick(const std::string& setPath, const GridSetManifest& set, const Scene& scene, const Grid& plan,
                      const std::array<uint32_t, 3>& index, std::span<const uint32_t> candidates,
                      const VoxelizeOptions& options, VoxelizeStats* stats) {
  VoxelizeStats brickStats;
  const Grid grid =
      voxelizeBrick(scene, plan, brickWindow(plan.dims, set.bricks, index), candidates, options, &brickStats);
  if (stats) {
    stats->cellsTested += brickStats.cellsTested;
    stats->exactFallbacks += brickStats.exactFallbacks;
    stats->seconds += brickStats.seconds;
  }
  if (grid.occupiedCount() == 0) {
    BrickEntry e;
    e.index = index;
    return e;
  }
  return writeBrickFile(setPath, set, index, grid);
}

void writeGridSetManifest(const std::string& setPath, const GridSetManifest& manifest) {
  GridSetManifest m = manifest;
  std::erase_if(m.entries, [](const BrickEntry& e) { return e.occupied == 0 && e.solid == 0; });
  std::sort(m.entries.begin(), m.entries.end(), [&](const BrickEntry& a, const BrickEntry& b) {
    return brickNumber(m.bricks, a.index) < brickNumber(m.bricks, b.index);
  });
  writeFileAtomically(setPath, encodeGridSetManifest(m));
}

GridSetManifest writeGridSet(const std::string& setPath, const Scene& scene, const VoxelizeOptions& options,
                             const std::array<uint32_t, 3>& bricks, VoxelizeStats* stats, const FillOptions* fill,
                             FillReport* fillReport) {
  Grid plan = planGrid(scene, options);
  checkBrickCounts(plan.dims, bricks);
  if (options.bounds) plan.outsidePrims = primitivesOutside(scene, plan);
  const auto candidates = brickCandidates(scene, plan, bricks, options.memoryLimitBytes);
  makeBrickFolder(setPath);
  GridSetManifest m{plan.bounds, plan.dims, plan.method, bricks, writeGridSetScene(setPath, scene, plan), {}};
  VoxelizeOptions brickOptions = options;
  brickOptions.progress = nullptr;
  for (uint64_t b = 0; b < candidates.size(); ++b) {
    if (options.progress && !options.progress(double(b) / double(candidates.size())))
      fail<Error>("voxelization cancelled");
    if (candidates[b].empty()) continue;
    const BrickEntry e = writeBrick(setPath, m, scene, plan, brickIndex(bricks, b), candidates[b], brickOptions, stats);
    if (e.occupied > 0) m.entries.push_back(e);
  }
  if (options.progress) options.progress(1.0);
  if (fill) {
    const FillReport report = fillGridSet(setPath, m, scene, *fill);
    if (fillReport) *fillReport = report;
  }
  writeGridSetManifest(setPath, m);
  return m;
}

}  // namespace vox
