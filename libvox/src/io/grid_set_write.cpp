// Writing a grid set: each brick voxelized and written before the next starts (so one brick's cells are in memory at
// a time), the manifest last (so a failure anywhere leaves no manifest).
#include <cstring>
#include <filesystem>
#include <system_error>

#include "vox/core/error.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"

namespace vox {

namespace {

std::string brickFolderName(const std::string& setPath) {
  return std::filesystem::path(setPath).stem().string() + ".bricks";
}

uint64_t headerChecksum(const std::string& fileBytes) {
  uint64_t c = 0;
  std::memcpy(&c, fileBytes.data() + 24, 8);  // docs/grid-format.md: the header's checksum field
  return c;
}

}  // namespace

std::string brickFileName(const std::string& setPath, const std::array<uint32_t, 3>& index) {
  return brickFolderName(setPath) + "/b_" + std::to_string(index[0]) + "_" + std::to_string(index[1]) + "_" +
         std::to_string(index[2]) + ".vgrid";
}

void makeBrickFolder(const std::string& setPath) {
  const auto folder = std::filesystem::path(setPath).parent_path() / brickFolderName(setPath);
  std::error_code ec;
  // A device or FIFO can take a grid's bytes but not a set: its bricks would go into /dev.
  if (std::filesystem::exists(setPath, ec) && !std::filesystem::is_regular_file(setPath, ec))
    fail<OutputError>(setPath, ": cannot write: a grid set's manifest must be a regular file");
  std::filesystem::create_directory(folder, ec);
  if (ec || !std::filesystem::is_directory(folder, ec))
    fail<OutputError>(folder.string(), ": cannot create the brick folder",
                      ec ? ": " + ec.message() : std::string(": a file of that name is in the way"));
}

BrickEntry writeBrick(const std::string& setPath, const Scene& scene, const Grid& plan,
                      const std::array<uint32_t, 3>& bricks, const std::array<uint32_t, 3>& index,
                      std::span<const uint32_t> candidates, const VoxelizeOptions& options, VoxelizeStats* stats,
                      bool writeEmpty) {
  VoxelizeStats brickStats;
  const Grid grid = voxelizeBrick(scene, plan, brickWindow(plan.dims, bricks, index), candidates, options,
                                  &brickStats);
  if (stats) {
    stats->cellsTested += brickStats.cellsTested;
    stats->exactFallbacks += brickStats.exactFallbacks;
    stats->seconds += brickStats.seconds;
  }
  BrickEntry e;
  e.index = index;
  e.occupied = grid.occupiedCount();
  e.references = grid.referenceCount();
  if (e.occupied == 0 && !writeEmpty) return e;
  e.file = brickFileName(setPath, index);
  const std::string bytes = encodeGridFile(scene, grid);
  e.fileSize = bytes.size();
  e.fileChecksum = headerChecksum(bytes);
  writeFileAtomically((std::filesystem::path(setPath).parent_path() / e.file).string(), bytes);
  return e;
}

void writeGridSetManifest(const std::string& setPath, const GridSetManifest& manifest) {
  GridSetManifest m = manifest;
  std::erase_if(m.entries, [](const BrickEntry& e) { return e.occupied == 0; });
  if (m.entries.empty()) {
    for (const BrickEntry& e : manifest.entries)
      if (!e.file.empty()) m.entries.push_back(e);
    VOX_CHECK(m.entries.size() == 1);
  }
  writeFileAtomically(setPath, encodeGridSetManifest(m));
}

GridSetManifest writeGridSet(const std::string& setPath, const Scene& scene, const VoxelizeOptions& options,
                             const std::array<uint32_t, 3>& bricks, VoxelizeStats* stats) {
  Grid plan = planGrid(scene, options);
  checkBrickCounts(plan.dims, bricks);
  if (options.bounds) plan.outsidePrims = primitivesOutside(scene, plan);
  const auto candidates = brickCandidates(scene, plan, bricks, options.memoryLimitBytes);
  makeBrickFolder(setPath);
  GridSetManifest m{plan.bounds, plan.dims, plan.method, bricks, {}};
  VoxelizeOptions brickOptions = options;
  brickOptions.progress = nullptr;
  for (uint64_t b = 0; b < candidates.size(); ++b) {
    if (options.progress && !options.progress(double(b) / double(candidates.size())))
      fail<Error>("voxelization cancelled");
    if (candidates[b].empty()) continue;
    m.entries.push_back(writeBrick(setPath, scene, plan, bricks, brickIndex(bricks, b), candidates[b], brickOptions,
                                   stats));
  }
  bool any = false;
  for (const BrickEntry& e : m.entries) any = any || e.occupied > 0;
  // The scene lives in the brick files: a set without occupied cells still writes brick (0,0,0), empty.
  if (!any) {
    m.entries.clear();
    m.entries.push_back(writeBrick(setPath, scene, plan, bricks, {0, 0, 0}, {}, brickOptions, stats, true));
  }
  writeGridSetManifest(setPath, m);
  if (options.progress) options.progress(1.0);
  std::erase_if(m.entries, [&](const BrickEntry& e) { return e.file.empty(); });
  return m;
}

}  // namespace vox
