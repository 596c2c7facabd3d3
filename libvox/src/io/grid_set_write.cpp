// Writing a grid set's files: a generation folder of its own, the scene file, brick files, the manifest last (so a
// failure anywhere leaves the old set, or none), then the old set's files removed. What goes into the bricks is the
// sets stage's (sets/voxelize_set.cpp, sets/fill_set.cpp).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string_view>
#include <system_error>

#include "io/grid_set_header.h"
#include "vox/core/memory_budget.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"

namespace vox {

namespace {

namespace fs = std::filesystem;

std::string brickFolderName(const std::string& setPath) { return fs::path(setPath).stem().string() + ".bricks"; }

std::string besideManifest(const std::string& setPath, const std::string& file) {
  return (fs::path(setPath).parent_path() / file).string();
}

// 64 random bits: two outputs, two runs, or two ranks of two runs never pick the same generation folder (and the
// folder is created exclusively, so a clash costs another name, never a shared file).
std::string randomGeneration() {
  std::random_device device;
  const uint64_t bits = (uint64_t(device()) << 32) ^ uint64_t(device());
  char hex[20];
  std::snprintf(hex, sizeof hex, "g%016llx", static_cast<unsigned long long>(bits));
  return hex;
}

// Makes NAME.bricks/ when missing (it may hold other manifests' generations) and a new generation folder in it.
std::unique_ptr<TemporaryFolder> makeGenerationFolder(const std::string& setPath, std::string& folder) {
  const fs::path parent = fs::path(setPath).parent_path() / brickFolderName(setPath);
  std::error_code ec;
  if (fs::create_directory(parent, ec)) syncParentFolder(parent.string());
  if (ec || !fs::is_directory(parent, ec))
    fail<OutputError>(parent.string(), ": cannot create the brick folder",
                      ec ? ": " + ec.message() : std::string(": a file of that name is in the way"));
  for (int attempt = 0;; ++attempt) {
    folder = brickFolderName(setPath) + "/" + randomGeneration();
    if (fs::exists(besideManifest(setPath, folder), ec) && attempt < 8) continue;
    return std::make_unique<TemporaryFolder>(besideManifest(setPath, folder), true);
  }
}

// Consumes from `s` a run of `min` to `max` characters that satisfy `is`; false (s unchanged) when there is none.
template <typename Is>
bool eat(std::string_view& s, size_t min, size_t max, Is&& is) {
  size_t n = 0;
  while (n < s.size() && n < max && is(s[n])) ++n;
  if (n < min) return false;
  s.remove_prefix(n);
  return true;
}

bool eatText(std::string_view& s, std::string_view text) {
  if (s.substr(0, text.size()) != text) return false;
  s.remove_prefix(text.size());
  return true;
}

// Whether `file` (a name the old manifest lists) is a name of the set layout of `setPath`: NAME.bricks/LEAF or
// NAME.bricks/gHEX/LEAF, LEAF scene.vgrid or b_X_Y_Z.vgrid (HEX 16 lower-case hex digits, X, Y, Z 1 to 10 digits).
// Nothing else is ever removed. (Matched by hand: std::regex set off GCC 12's -Wmaybe-uninitialized at -O1.)
bool isSetLayoutName(const std::string& setPath, const std::string& file) {
  std::string_view s(file);
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  const auto hex = [&](char c) { return digit(c) || (c >= 'a' && c <= 'f'); };
  if (!eatText(s, brickFolderName(setPath) + "/")) return false;
  if (s.size() > 18 && s[0] == 'g' && s[17] == '/') {
    s.remove_prefix(1);
    if (!eat(s, 16, 16, hex) || !eatText(s, "/")) return false;
  }
  if (eatText(s, "scene.vgrid")) return s.empty();
  return eatText(s, "b_") && eat(s, 1, 10, digit) && eatText(s, "_") && eat(s, 1, 10, digit) && eatText(s, "_") &&
         eat(s, 1, 10, digit) && eatText(s, ".vgrid") && s.empty();
}

// Removes `path` when it is a regular file (not a link) of `size` bytes whose header holds `checksum`.
void removeListedFile(const std::string& path, uint64_t size, uint64_t checksum) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(path, ec)) || fs::file_size(path, ec) != size || ec) return;
  std::ifstream in(path, std::ios::binary);
  char header[kSetHeaderSize] = {};
  if (!in.read(header, sizeof header)) return;
  if (headerChecksum(std::string(header, sizeof header)) != checksum) return;
  in.close();
  fs::remove(path, ec);
}

}  // namespace

std::string brickFileName(const GridSetManifest& set, const std::array<uint32_t, 3>& index) {
  return (fs::path(set.scene.file).parent_path() / ("b_" + std::to_string(index[0]) + "_" + std::to_string(index[1]) +
                                                    "_" + std::to_string(index[2]) + ".vgrid"))
      .string();
}

std::string sceneFileName(const std::string& folder) { return folder + "/scene.vgrid"; }

void checkGridSetOutput(const std::string& setPath) {
  // The manifest names the bricks by this folder, and readers refuse names with control bytes: refuse them before
  // writing a set no reader takes.
  if (hasControlByte(brickFolderName(setPath)))
    fail<OutputError>(quoteInput(setPath, 200), ": cannot write a grid set whose name holds control characters");
  std::error_code ec;
  // A device or FIFO can take a grid's bytes but not a set: its bricks would go into /dev.
  if (fs::exists(setPath, ec) && !fs::is_regular_file(setPath, ec))
    fail<OutputError>(setPath, ": cannot write: a grid set's manifest must be a regular file");
  if (fs::path(setPath).filename().string() == brickFolderName(setPath))
    fail<OutputError>(setPath, ": cannot write a grid set under this name: its bricks go into the folder ",
                      brickFolderName(setPath), " of the same name (name the set NAME.vgrid)");
}

std::optional<GridSetManifest> previousGridSet(const std::string& path) {
  try {
    if (isGridSet(path)) return readGridSetManifest(path);
  } catch (const Error&) {
    // Missing, unreadable or corrupt: nothing this output can tell apart as a set's files.
  }
  return std::nullopt;
}

void removeGridSetFiles(const std::string& setPath, const GridSetManifest& old) {
  std::vector<std::string> folders;
  auto remove = [&](const std::string& file, uint64_t size, uint64_t checksum) {
    if (!isSetLayoutName(setPath, file)) return;
    removeListedFile(besideManifest(setPath, file), size, checksum);
    const std::string folder = fs::path(file).parent_path().string();
    if (folder != brickFolderName(setPath) && std::find(folders.begin(), folders.end(), folder) == folders.end())
      folders.push_back(folder);
  };
  remove(old.scene.file, old.scene.fileSize, old.scene.checksum);
  for (const BrickEntry& e : old.entries) remove(e.file, e.fileSize, e.fileChecksum);
  std::error_code ec;
  for (const std::string& folder : folders) fs::remove(besideManifest(setPath, folder), ec);  // only when empty
}

GridSetOutput::GridSetOutput(const std::string& setPath, const std::string& folder) : setPath_(setPath) {
  checkGridSetOutput(setPath);
  if (folder.empty()) {
    previous_ = previousGridSet(setPath);
    files_ = makeGenerationFolder(setPath, folder_);
  } else {
    folder_ = folder;
    files_ = std::make_unique<TemporaryFolder>(besideManifest(setPath, folder), false);
  }
}

void GridSetOutput::commit(const GridSetManifest& manifest) {
  VOX_CHECK(fs::path(manifest.scene.file).parent_path().string() == folder_);
  writeGridSetManifest(setPath_, manifest);
  files_->keep();
  if (previous_) removeGridSetFiles(setPath_, *previous_);
  previous_.reset();
}

GridSetScene writeGridSetScene(const std::string& setPath, const std::string& folder, const Scene& scene,
                               const Grid& plan, bool write) {
  Grid g = emptyGridLike(plan);
  g.outsidePrims = plan.outsidePrims;
  const std::string bytes = encodeGridFile(scene, g);
  GridSetScene s{sceneFileName(folder), bytes.size(), headerChecksum(bytes)};
  if (write) writeFileAtomically(besideManifest(setPath, s.file), bytes);
  return s;
}

BrickEntry writeBrickFile(const std::string& setPath, const GridSetManifest& set, const std::array<uint32_t, 3>& index,
                          const Grid& cells) {
  BrickEntry e;
  e.index = index;
  e.file = brickFileName(set, index);
  e.occupied = cells.occupiedCount();
  e.references = cells.referenceCount();
  e.solid = cells.solidCount();
  const std::string bytes = encodeBrickFile(set, index, cells);
  e.fileSize = bytes.size();
  e.fileChecksum = headerChecksum(bytes);
  writeFileAtomically(besideManifest(setPath, e.file), bytes);
  return e;
}

void checkGridSetHolds(const Grid& grid, const std::string& what) {
  const bool sdf = grid.sdfHalfWidth != 0 || !grid.sdfKeys.empty(), fractions = !grid.fractions.empty();
  if (!sdf && !fractions) return;
  fail<UsageError>(what, ": a grid set holds no signed distances or volume fractions, and this grid has ",
                   sdf && fractions ? "both" : (sdf ? "signed distances" : "volume fractions"), ": save it without ",
                   what, " (a single .vgrid holds them) or voxelize without sdf and fraction");
}

namespace {

// The cells of one layer of bricks, [c0, c1) of `grid`'s, ordered by brick (bx + BX by) by a counting sort that
// keeps each brick's keys ascending: brick i holds order[start[i] .. start[i + 1]).
struct LayerOrder {
  std::vector<uint64_t> start;
  std::vector<size_t> order;

  LayerOrder(const Grid& grid, const std::array<uint32_t, 3>& bricks, size_t c0, size_t c1)
      : start(uint64_t(bricks[0]) * bricks[1] + 1, 0), order(c1 - c0) {
    auto brickOf = [&](size_t c) {
      const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
      return brickOfCell(ijk[0], grid.dims[0], bricks[0]) +
             uint64_t(bricks[0]) * brickOfCell(ijk[1], grid.dims[1], bricks[1]);
    };
    for (size_t c = c0; c < c1; ++c) ++start[brickOf(c) + 1];
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<uint64_t> next(start.begin(), start.end() - 1);
    for (size_t c = c0; c < c1; ++c) order[next[brickOf(c)]++] = c;
  }
};

// Brick `i` of a layer: its cells (order[start[i] .. start[i + 1])) with their primitive lists, and `runs`.
Grid brickCells(const Grid& grid, const LayerOrder& layer, uint64_t i, std::vector<CellRun> runs) {
  Grid b = emptyGridLike(grid);
  const uint64_t n = layer.start[i + 1] - layer.start[i];
  b.cellKeys.reserve(n);
  b.cellStart.reserve(n + 1);
  for (uint64_t k = layer.start[i]; k < layer.start[i + 1]; ++k) {
    const size_t c = layer.order[k];
    b.cellKeys.push_back(grid.cellKeys[c]);
    const auto prims = grid.cellPrims(c);
    b.primIds.insert(b.primIds.end(), prims.begin(), prims.end());
    b.cellStart.push_back(b.primIds.size());
  }
  b.solidRuns = std::move(runs);
  return b;
}

}  // namespace

GridSetManifest writeGridAsSet(const std::string& setPath, const Scene& scene, const Grid& grid,
                               const std::array<uint32_t, 3>& bricks, const std::function<bool(double)>& progress) {
  checkGridSetHolds(grid, "bricks");
  checkBrickCounts(grid.dims, bricks);
  checkGridSetOutput(setPath);
  VOX_CHECK(grid.cellStart.size() == grid.occupiedCount() + 1);
  const uint64_t plane = uint64_t(grid.dims[0]) * grid.dims[1], perLayer = uint64_t(bricks[0]) * bricks[1];
  // LayerOrder's counts and order (bricks of a layer by the million, say 2048 x 2048), before any file is touched.
  checkMemory(double(perLayer) * 16 + double(grid.occupiedCount()) * 8, setPath, "splitting the grid into bricks");
  auto runs = splitRunsByBrick(grid.solidRuns, grid.dims, bricks);
  GridSetOutput output(setPath);
  GridSetManifest m{
      grid.bounds, grid.dims, grid.method, bricks, writeGridSetScene(setPath, output.folder(), scene, grid), {}};
  size_t c0 = 0, r = 0;  // the layer's first cell; the next brick of `runs`
  for (uint32_t bz = 0; bz < bricks[2]; ++bz) {
    const uint64_t endKey = uint64_t(brickWindow(grid.dims, bricks, {0, 0, bz}).end[2]) * plane;
    const size_t c1 = size_t(std::lower_bound(grid.cellKeys.begin() + ptrdiff_t(c0), grid.cellKeys.end(), endKey) -
                             grid.cellKeys.begin());
    const LayerOrder layer(grid, bricks, c0, c1);
    c0 = c1;
    for (uint64_t i = 0; i < perLayer; ++i) {
      if (progress && !progress((double(bz) + double(i) / double(perLayer)) / double(bricks[2])))
        fail<Error>("save cancelled");
      const std::array<uint32_t, 3> index{uint32_t(i % bricks[0]), uint32_t(i / bricks[0]), bz};
      std::vector<CellRun> brickRuns;
      if (r < runs.size() && runs[r].first == brickNumber(bricks, index)) brickRuns = std::move(runs[r++].second);
      if (layer.start[i + 1] == layer.start[i] && brickRuns.empty()) continue;
      m.entries.push_back(writeBrickFile(setPath, m, index, brickCells(grid, layer, i, std::move(brickRuns))));
    }
  }
  // The set is the grid by construction; its totals are checked all the same, before it replaces anything.
  uint64_t occupied = 0, references = 0, solid = 0;
  for (const BrickEntry& e : m.entries) occupied += e.occupied, references += e.references, solid += e.solid;
  VOX_CHECK(occupied == grid.occupiedCount() && references == grid.referenceCount() && solid == grid.solidCount());
  if (progress && !progress(1.0)) fail<Error>("save cancelled");
  output.commit(m);
  return m;
}

void writeGridSetManifest(const std::string& setPath, const GridSetManifest& manifest) {
  GridSetManifest m = manifest;
  std::erase_if(m.entries, [](const BrickEntry& e) { return e.occupied == 0 && e.solid == 0; });
  std::sort(m.entries.begin(), m.entries.end(), [&](const BrickEntry& a, const BrickEntry& b) {
    return brickNumber(m.bricks, a.index) < brickNumber(m.bricks, b.index);
  });
  writeFileAtomically(setPath, encodeGridSetManifest(m));
}

}  // namespace vox
