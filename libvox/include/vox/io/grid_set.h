// Grid sets (issue 13): one grid split into bricks of whole cells, one grid file per non-empty brick, named by a
// small checksummed manifest. Layout in docs/grid-format.md "Grid sets".
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vox/io/grid_file.h"
#include "vox/voxelize/bricks.h"
#include "vox/voxelize/voxelize.h"

namespace vox {

inline constexpr uint32_t kGridSetVersion = 1;

// One written brick as the manifest lists it.
struct BrickEntry {
  std::array<uint32_t, 3> index{0, 0, 0};  // brick (bx, by, bz)
  std::string file;                        // relative to the manifest's folder: "NAME.bricks/b_X_Y_Z.vgrid"
  uint64_t fileSize = 0;                   // bytes of the brick file
  uint64_t fileChecksum = 0;               // the checksum in the brick file's header (ties the file to this set)
  uint64_t occupied = 0;                   // occupied cells of the brick
  uint64_t references = 0;                 // references of the brick
};

// What a manifest holds: the whole grid's plan (bounds, dims, method), the brick counts and the written bricks,
// ascending by brick index (x fastest).
struct GridSetManifest {
  Box bounds;
  std::array<uint32_t, 3> dims{1, 1, 1};
  OverlapMethod method = OverlapMethod::Exact;
  std::array<uint32_t, 3> bricks{1, 1, 1};
  std::vector<BrickEntry> entries;
};

// ---- Writing ----

// The relative file name of a brick of the set at `setPath`: "NAME.bricks/b_X_Y_Z.vgrid" (NAME the manifest's
// file name without its last extension).
std::string brickFileName(const std::string& setPath, const std::array<uint32_t, 3>& index);
// Creates the folder the bricks of `setPath` go into (NAME.bricks beside it). Throws OutputError.
void makeBrickFolder(const std::string& setPath);

// Voxelizes brick `index` of the planned grid and, when it has occupied cells, writes its grid file (the whole
// scene, the whole grid's bounds, dims and outsidePrims, the brick's cells with their whole-grid keys) beside the
// manifest. Returns its entry; occupied == 0 means nothing was written (unless `writeEmpty`). Throws as voxelizeBrick and OutputError.
BrickEntry writeBrick(const std::string& setPath, const Scene& scene, const Grid& plan,
                      const std::array<uint32_t, 3>& bricks, const std::array<uint32_t, 3>& index,
                      std::span<const uint32_t> candidates, const VoxelizeOptions& options,
                      VoxelizeStats* stats = nullptr, bool writeEmpty = false);

// Writes the manifest (atomically: a failure leaves no manifest). Entries with occupied == 0 are left out; a set
// without any occupied cell still needs the scene, so `entries` must then hold brick (0,0,0), written anyway.
void writeGridSetManifest(const std::string& setPath, const GridSetManifest& manifest);

// The whole job on one process: plan, candidates, each brick voxelized and written before the next starts, then the
// manifest. `progress` (may be empty) gets the fraction of bricks done. Returns the manifest written.
GridSetManifest writeGridSet(const std::string& setPath, const Scene& scene, const VoxelizeOptions& options,
                             const std::array<uint32_t, 3>& bricks, VoxelizeStats* stats = nullptr);

// ---- Reading ----

// Encoding of a manifest (docs/grid-format.md); decode checks magic, version, flags, size, checksum, every count,
// brick indices (in range, strictly ascending), names (relative, inside the manifest's folder) and the totals.
std::string encodeGridSetManifest(const GridSetManifest& manifest);
GridSetManifest decodeGridSetManifest(const std::string& bytes, const std::string& name);
GridSetManifest readGridSetManifest(const std::string& path);

// Reads one brick of a set and checks it against the manifest: size and checksum as listed, the same bounds, dims
// and method, every cell inside the brick, the counts as listed. Throws InputError naming the brick file.
GridFile readBrick(const std::string& setPath, const GridSetManifest& manifest, size_t entry);

// The whole grid of a set in memory: the bricks' cells merged (they are disjoint and ordered by key within a
// brick). Equal to the grid the single-process voxelizer makes. Throws InputError for a corrupt set, LimitError when
// it cannot fit the memory budget.
GridFile readGridSet(const std::string& path);

// Whether the file at `path` starts with the manifest's magic. Throws InputError when it cannot be read.
bool isGridSet(const std::string& path);
// readGridSet for a manifest, readGridFile otherwise: what the tools load.
GridFile readGridOrSet(const std::string& path);

}  // namespace vox
