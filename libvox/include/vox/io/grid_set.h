// Grid sets (issue 13): one grid split into bricks of whole cells. The scene is stored once, in a scene file; each
// non-empty brick is a brick file holding only its cells, primitive lists and solid runs; a small checksummed
// manifest names them all. Layout in docs/grid-format.md "Grid sets". The files only: voxelizing a scene into a set
// and filling one are the sets stage's (vox/sets/).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vox/core/brick_layout.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"

namespace vox {

// Version 2: the scene in one scene file, bricks as brick files (version 1 put the whole scene in every brick).
inline constexpr uint32_t kGridSetVersion = 2;
inline constexpr uint32_t kBrickFileVersion = 1;

// The set's scene file: a grid file holding the scene, the whole grid's bounds, dims, method and outsidePrims, and
// no cells. Brick files name it and carry its checksum, so a brick is never read against another scene.
struct GridSetScene {
  std::string file;       // relative to the manifest's folder: "NAME.bricks/scene.vgrid"
  uint64_t fileSize = 0;  // bytes of the scene file
  uint64_t checksum = 0;  // the checksum in its header
};

// One written brick as the manifest lists it.
struct BrickEntry {
  std::array<uint32_t, 3> index{0, 0, 0};  // brick (bx, by, bz)
  std::string file;                        // relative to the manifest's folder: "NAME.bricks/b_X_Y_Z.vgrid"
  uint64_t fileSize = 0;                   // bytes of the brick file
  uint64_t fileChecksum = 0;               // the checksum in the brick file's header (ties the file to this set)
  uint64_t occupied = 0;                   // occupied cells of the brick
  uint64_t references = 0;                 // references of the brick
  uint64_t solid = 0;                      // solid cells of the brick (--fill)
};

// What a manifest holds: the whole grid's plan (bounds, dims, method), the brick counts, the scene file and the
// written bricks, ascending by brick index (x fastest).
struct GridSetManifest {
  Box bounds;
  std::array<uint32_t, 3> dims{1, 1, 1};
  OverlapMethod method = OverlapMethod::Exact;
  std::array<uint32_t, 3> bricks{1, 1, 1};
  GridSetScene scene;
  std::vector<BrickEntry> entries;
};

// A grid without cells on the plan of `plan` (a Grid or a GridSetManifest: both carry bounds, dims and method).
template <typename Plan>
Grid emptyGridLike(const Plan& plan) {
  Grid g;
  g.bounds = plan.bounds;
  g.dims = plan.dims;
  g.method = plan.method;
  return g;
}

// ---- Writing ----
// A set is replaced as a whole or not at all. Its files go into a generation folder of their own,
// NAME.bricks/gHEX/ (NAME the manifest's file name without its last extension, HEX 16 random hex digits, the folder
// created new), which the old set's manifest cannot name; the manifest is renamed into place last; only then are
// the old set's files removed. A failure or signal before that leaves the old set whole and removes the new folder.
// Two manifests in one folder never share a file, whatever their names.

// The relative names of a brick and of the scene file inside a set's generation folder `folder` (relative to the
// manifest's folder): "FOLDER/b_X_Y_Z.vgrid" and "FOLDER/scene.vgrid". brickFileName takes the folder from the set's
// scene file.
std::string brickFileName(const GridSetManifest& set, const std::array<uint32_t, 3>& index);
std::string sceneFileName(const std::string& folder);

// Refuses, before any work, an output that cannot be a set's manifest: a name holding control bytes (readers refuse
// them), an existing node that is not a regular file (a device would send the bricks to /dev), or a name that is
// its own brick folder ("foo.bricks": the folder foo.bricks/ would take the manifest's place). Throws OutputError.
void checkGridSetOutput(const std::string& setPath);

// The set at `path` that a new output there will replace, when `path` holds a readable manifest.
std::optional<GridSetManifest> previousGridSet(const std::string& path);

// Removes the files of `old`, a set whose manifest at `setPath` has been replaced: only names of the set layout
// (NAME.bricks/scene.vgrid, NAME.bricks/b_X_Y_Z.vgrid, and the same inside NAME.bricks/gHEX/) whose size and header
// checksum are the ones `old` lists, then their generation folders when empty. Never throws: what cannot be
// removed stays.
void removeGridSetFiles(const std::string& setPath, const GridSetManifest& old);

// One set being written: the output checked, the set it replaces read, the generation folder made (or, on MPI
// ranks other than the writer, the folder that rank made registered for removal on a signal). Destroying it before
// commit() removes the generation folder (writer only), so an exception anywhere leaves the old set as it was.
// @throw OutputError when the output is refused (checkGridSetOutput) or the folders cannot be made.
class GridSetOutput {
 public:
  // `folder` empty: this process makes the generation folder. Otherwise the folder another rank made (folder()).
  explicit GridSetOutput(const std::string& setPath, const std::string& folder = {});
  // The generation folder, relative to the manifest's folder ("NAME.bricks/gHEX").
  const std::string& folder() const { return folder_; }
  // Writes `manifest` over the output (writeGridSetManifest), then removes the files of the set it replaced.
  void commit(const GridSetManifest& manifest);

 private:
  std::string setPath_;
  std::string folder_;
  std::optional<GridSetManifest> previous_;
  std::unique_ptr<TemporaryFolder> files_;
};

// Encodes the scene file of `scene` and the planned grid `plan` (bounds, dims, method, outsidePrims; its cells are
// ignored) and, when `write`, writes it into the generation folder `folder` (GridSetOutput::folder()). Every process
// computes the same name, size and checksum, so ranks that do not write it can still reference it. Throws OutputError.
GridSetScene writeGridSetScene(const std::string& setPath, const std::string& folder, const Scene& scene,
                               const Grid& plan, bool write = true);

// Writes brick `index` of `set` (plan, bricks and scene file taken from it) holding the cells and solid runs of
// `cells` (whole-grid keys, all inside the brick). Returns its entry. Throws OutputError.
BrickEntry writeBrickFile(const std::string& setPath, const GridSetManifest& set, const std::array<uint32_t, 3>& index,
                          const Grid& cells);

// Refuses a grid that a set cannot hold whole: a set's bricks hold cells, primitive lists and solid runs, no signed
// distances and no volume fractions, which a grid set would drop. Throws UsageError naming `what` (the argument).
void checkGridSetHolds(const Grid& grid, const std::string& what);

// Writes `grid` and `scene` (the scene it was voxelized from) as a grid set of `bricks`: the grid's own cells,
// primitive lists and solid runs split at brick faces, not a new voxelization, so the set read back is `grid`, cell
// for cell and run for run (whatever fill made its solid cells). One layer of bricks (one bz) is ordered at a time,
// 8 bytes a cell of the layer. Every check is made before the manifest replaces the old output (GridSetOutput), so a
// refusal, an error or a cancel (`progress`, given the fraction done, returning false: vox::Error) leaves it whole.
// Throws UsageError (checkGridSetHolds, checkBrickCounts) before any file is touched, OutputError as GridSetOutput.
GridSetManifest writeGridAsSet(const std::string& setPath, const Scene& scene, const Grid& grid,
                               const std::array<uint32_t, 3>& bricks, const std::function<bool(double)>& progress = {});

// Writes the manifest (atomically: a failure leaves the old one). Entries without cells are left out. Prefer
// GridSetOutput::commit, which also removes the replaced set's files.
void writeGridSetManifest(const std::string& setPath, const GridSetManifest& manifest);

// ---- Reading ----

// Encoding of a manifest (docs/grid-format.md); decode checks magic, version, flags, size, checksum, every count,
// brick indices (in range, strictly ascending), names and the totals. A version 1 manifest is refused with a
// message saying to voxelize again.
std::string encodeGridSetManifest(const GridSetManifest& manifest);
GridSetManifest decodeGridSetManifest(const std::string& bytes, const std::string& name);
GridSetManifest readGridSetManifest(const std::string& path);

// The set's scene file: size and checksum as listed, the manifest's bounds, dims and method, no cells. Returns the
// scene and the grid without cells (bounds, dims, method, outsidePrims). Throws InputError naming the scene file.
GridFile readGridSetScene(const std::string& setPath, const GridSetManifest& manifest);

// Brick files: encoding and decoding (docs/grid-format.md "Brick file"). decodeBrickFile checks the header, that
// the brick names the manifest's scene file with its checksum, the plan, the index, every cell and solid run inside
// the brick, primitive ids below `boundedCount`, and the counts against `entry`. Throws InputError naming `name`.
std::string encodeBrickFile(const GridSetManifest& set, const std::array<uint32_t, 3>& index, const Grid& cells);
Grid decodeBrickFile(const std::string& bytes, const std::string& name, const GridSetManifest& set,
                     const BrickEntry& entry, uint64_t boundedCount);

// Reads one brick of a set: its file (inside the manifest's folder, size and checksum as listed) decoded as above,
// primitive ids checked against the scene's `boundedCount` (Scene::boundedCount). Returns the brick's cells with
// whole-grid keys (bounds, dims, method of the whole grid; no outsidePrims).
Grid readBrick(const std::string& setPath, const GridSetManifest& manifest, size_t entry, uint64_t boundedCount);

// What forEachGridSetLayer hands over of a layer's cells: sorted by key with their primitive lists (vox-info
// --cells), in brick order with their lists (totals, which need no order), sorted keys alone, cellStart and
// primIds left empty (voxel rows, for binvox: no primitive list is kept or moved), or sorted keys with their
// primitive counts: cellStart as if the lists were there (cell c holds cellStart[c + 1] - cellStart[c]
// primitives) but primIds left empty (.vox colours by count: 8 bytes a cell more than the keys, no lists).
enum class LayerCells : uint8_t { Sorted, BrickOrder, KeysOnly, KeysAndCounts };

// Streams a set in cell-key order, one layer of bricks at a time (all bricks with one bz: cells are ordered x
// fastest, so the cells of a layer's bricks interleave): `visit` gets each layer's cells as `cells` says and its
// solid runs sorted, merged within the layer. Peak memory is one layer, not the grid. Throws as readBrick.
void forEachGridSetLayer(const std::string& setPath, const GridSetManifest& manifest, const GridFile& sceneFile,
                         const std::function<void(const Grid& layer)>& visit, LayerCells cells = LayerCells::Sorted);

// The whole grid of a set in memory: the bricks' cells merged. Equal to the grid the single-process voxelizer
// makes. Throws InputError for a corrupt set, LimitError when it cannot fit the memory budget.
GridFile readGridSet(const std::string& path);

// Whether the file at `path` starts with the manifest's magic. Throws InputError when it cannot be read.
bool isGridSet(const std::string& path);
// readGridSet for a manifest, readGridFile otherwise: what the tools load. A brick file named directly is refused
// with a message naming its manifest's role. `progress`: readGridFile's (a set is read without it).
GridFile readGridOrSet(const std::string& path, const std::function<bool(double)>& progress = {});

}  // namespace vox
