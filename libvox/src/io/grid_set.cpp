// Grid-set manifests and reading a set back (docs/grid-format.md "Grid sets"). The manifest is untrusted input like
// a grid file: every count, index and name is checked, and the scene file and bricks must lie inside the manifest's
// folder.
#include "vox/io/grid_set.h"

#include <algorithm>
#include <bit>
#include <filesystem>
#include <fstream>

#include "io/grid_set_header.h"
#include "vox/io/input_file.h"

namespace vox {

namespace {

void putEntry(ByteWriter& w, const BrickEntry& e) {
  for (uint32_t i : e.index) w.put(i);
  w.putString(e.file);
  w.put(e.fileSize);
  w.put(e.fileChecksum);
  w.put(e.occupied);
  w.put(e.references);
  w.put(e.solid);
}

BrickEntry getEntry(ByteReader& r) {
  BrickEntry e;
  for (uint32_t& i : e.index) i = r.get<uint32_t>();
  e.file = r.getString();
  e.fileSize = r.get<uint64_t>();
  e.fileChecksum = r.get<uint64_t>();
  e.occupied = r.get<uint64_t>();
  e.references = r.get<uint64_t>();
  e.solid = r.get<uint64_t>();
  return e;
}

// The plan part of a manifest, checked as a grid file's (dims in range, lo < hi, b(n) == hi).
void getPlan(ByteReader& r, GridSetManifest& m) {
  m.bounds.lo = r.getVec("bounds");
  m.bounds.hi = r.getVec("bounds");
  for (uint32_t& n : m.dims) {
    n = r.get<uint32_t>();
    if (n == 0 || n > kMaxCellsPerAxis) r.corrupt("grid dimension " + std::to_string(n) + " out of range");
  }
  const uint8_t method = r.get<uint8_t>();
  if (method > uint8_t(OverlapMethod::Exact)) r.corrupt("unknown overlap method " + std::to_string(method));
  m.method = OverlapMethod(method);
  for (int a = 0; a < 3; ++a)
    if (!(m.bounds.lo[a] < m.bounds.hi[a]) || cellBoundary(m.bounds, m.dims, a, m.dims[a]) != m.bounds.hi[a])
      r.corrupt("bounds do not divide into the grid's cells");
  for (uint32_t& b : m.bricks) b = r.get<uint32_t>();
  try {
    checkBrickCounts(m.dims, m.bricks);
  } catch (const UsageError& e) {
    r.corrupt(e.what());
  }
}

// Control bytes: fuzz/fuzz_grid.cpp found a brick named with a newline, which split the one-line error.
bool badName(const std::string& file) { return file.empty() || hasControlByte(file); }

// Entries in strictly ascending brick order, named, none empty, counts adding up to the totals.
void checkEntries(ByteReader& r, const GridSetManifest& m, uint64_t occupied, uint64_t references, uint64_t solid) {
  uint64_t sum[3] = {0, 0, 0};
  for (size_t i = 0; i < m.entries.size(); ++i) {
    const BrickEntry& e = m.entries[i];
    const std::string which = "brick " + std::to_string(i) + ": ";
    for (int a = 0; a < 3; ++a)
      if (e.index[a] >= m.bricks[a]) r.corrupt(which + "index out of range");
    if (i > 0 && brickNumber(m.bricks, e.index) <= brickNumber(m.bricks, m.entries[i - 1].index))
      r.corrupt("bricks not in ascending order");
    if (badName(e.file)) r.corrupt(which + "bad file name");
    if (e.occupied == 0 && e.solid == 0) r.corrupt(which + "empty brick listed");
    if (e.references < e.occupied || (e.occupied == 0) != (e.references == 0))
      r.corrupt(which + "references do not match the cells");
    // A brick file stores 16 bytes per cell (key, offset) and 4 per reference after its 32-byte header: counts its
    // listed size cannot hold are refused here, before a reader sizes anything by them.
    if (e.fileSize < kSetHeaderSize || e.occupied > e.fileSize / 16 || e.references > e.fileSize / 4 ||
        e.occupied * 16 + e.references * 4 > e.fileSize)
      r.corrupt(which + "cell counts larger than its file");
    const uint64_t add[3] = {e.occupied, e.references, e.solid};
    for (int k = 0; k < 3; ++k) {
      sum[k] += add[k];
      if (sum[k] < add[k]) r.corrupt("cell counts overflow");
    }
  }
  if (sum[0] != occupied || sum[1] != references || sum[2] != solid)
    r.corrupt("brick counts do not add up to the totals");
}

}  // namespace

std::string encodeGridSetManifest(const GridSetManifest& m) {
  ByteWriter w;
  w.putVec(m.bounds.lo);
  w.putVec(m.bounds.hi);
  for (uint32_t n : m.dims) w.put(n);
  w.put(uint8_t(m.method));
  for (uint32_t b : m.bricks) w.put(b);
  uint64_t occupied = 0, references = 0, solid = 0;
  for (const BrickEntry& e : m.entries) {
    occupied += e.occupied;
    references += e.references;
    solid += e.solid;
  }
  w.put(occupied);
  w.put(references);
  w.put(solid);
  w.putString(m.scene.file);
  w.put(m.scene.fileSize);
  w.put(m.scene.checksum);
  w.put(uint64_t(m.entries.size()));
  for (const BrickEntry& e : m.entries) putEntry(w, e);
  return withSetHeader(kSetMagic, kGridSetVersion, w.bytes());
}

GridSetManifest decodeGridSetManifest(const std::string& bytes, const std::string& name) {
  if (bytes.size() >= 12 && std::memcmp(bytes.data(), kSetMagic, 8) == 0 && bytes[8] == 1 && bytes[9] == 0 &&
      bytes[10] == 0 && bytes[11] == 0)
    fail<InputError>(name,
                     ": grid-set version 1 (every brick carried the whole scene) is no longer read: "
                     "voxelize the scene again with --bricks");
  checkSetHeader(bytes, name, kSetMagic, kGridSetVersion, "grid-set manifest");
  GridSetManifest m;
  ByteReader p(bytes, kSetHeaderSize, name);
  getPlan(p, m);
  const uint64_t occupied = p.get<uint64_t>();
  const uint64_t references = p.get<uint64_t>();
  const uint64_t solid = p.get<uint64_t>();
  m.scene.file = p.getString();
  if (badName(m.scene.file)) p.corrupt("bad scene file name");
  m.scene.fileSize = p.get<uint64_t>();
  m.scene.checksum = p.get<uint64_t>();
  // The smallest entry is 3 u32, an empty name's u32 and 5 u64.
  const uint64_t count = p.getCount(56, "brick");
  m.entries.reserve(count);
  for (uint64_t i = 0; i < count; ++i) m.entries.push_back(getEntry(p));
  if (!p.atEnd()) p.corrupt("trailing bytes after the bricks");
  checkEntries(p, m, occupied, references, solid);
  return m;
}

GridSetManifest readGridSetManifest(const std::string& path) {
  return decodeGridSetManifest(readInputFile(path, "grid-set manifest"), path);
}

namespace {

// Throws InputError naming `path` unless it is a regular file of the listed size (`role`: "brick", "scene file").
void requireListedSize(const std::string& setPath, const std::string& path, uint64_t size, const char* role) {
  requireRegularFile(path, role);
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != size || ec)
    fail<InputError>(path, ": not the ", role, " ", setPath, " names (size differs; rewritten since?)");
}

}  // namespace

GridFile readGridSetScene(const std::string& setPath, const GridSetManifest& m) {
  // Refuses absolute names and names leaving the manifest's folder (after "..", symbolic links included).
  const std::string path = resolveInsideFolder(setPath, m.scene.file);
  // The size first: a file put in its place (2 GiB, say) is refused before it is read.
  requireListedSize(setPath, path, m.scene.fileSize, "scene file");
  const std::string bytes = readInputFile(path, "grid-set scene file");
  if (bytes.size() != m.scene.fileSize || headerChecksum(bytes) != m.scene.checksum)
    fail<InputError>(path, ": not the scene file ", setPath, " names (size or checksum differ; rewritten since?)");
  GridFile file = decodeGridFile(bytes, path);
  const Grid& g = file.grid;
  auto same = [](const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  if (!same(g.bounds.lo, m.bounds.lo) || !same(g.bounds.hi, m.bounds.hi) || g.dims != m.dims || g.method != m.method)
    fail<InputError>(path, ": bounds, dims or method differ from its manifest ", setPath);
  if (g.occupiedCount() != 0 || !g.solidRuns.empty()) fail<InputError>(path, ": a set's scene file holds no cells");
  return file;
}

Grid readBrick(const std::string& setPath, const GridSetManifest& m, size_t entry, uint64_t boundedCount) {
  VOX_CHECK(entry < m.entries.size());
  const BrickEntry& e = m.entries[entry];
  const std::string path = resolveInsideFolder(setPath, e.file);
  const std::string bytes = readInputFile(path, "brick file");
  if (bytes.size() != e.fileSize || headerChecksum(bytes) != e.fileChecksum)
    fail<InputError>(path, ": not the brick ", setPath, " names (size or checksum differ; rewritten since?)");
  return decodeBrickFile(bytes, path, m, e, boundedCount);
}

namespace {

// The counts are the manifest's word until each brick is read: the files of entries [first, end) must be on disk at
// their listed sizes (which bound the counts, decodeGridSetManifest) before arrays are sized by them.
void requireListedBricks(const std::string& setPath, const GridSetManifest& m, size_t first, size_t end) {
  for (size_t i = first; i < end; ++i) {
    requireListedSize(setPath, resolveInsideFolder(setPath, m.entries[i].file), m.entries[i].fileSize, "brick file");
  }
}

// Appends a brick's cells to `whole`; the caller sorts when bricks interleave.
void appendBrick(Grid& whole, const Grid& brick) {
  whole.cellKeys.insert(whole.cellKeys.end(), brick.cellKeys.begin(), brick.cellKeys.end());
  const uint64_t base = whole.cellStart.back();  // primIds.size(), unless the lists were dropped (KeysAndCounts)
  for (size_t c = 1; c < brick.cellStart.size(); ++c) whole.cellStart.push_back(base + brick.cellStart[c]);
  whole.primIds.insert(whole.primIds.end(), brick.primIds.begin(), brick.primIds.end());
  whole.solidRuns.insert(whole.solidRuns.end(), brick.solidRuns.begin(), brick.solidRuns.end());
}

// Cells sorted by key with their counts (cellStart without primIds). Each count is packed under its key into one
// word when both fit (keys take bit_width(cells - 1) bits: 33 at 2048^3), so sorting the keys sorts the cells in
// place; otherwise (key, count) pairs are sorted, 16 bytes a cell more. Either is a direct sort: an indirect one
// (an order, then a sorted copy) took twice the time (perf: most of a .vox export of a set at 2048^3).
void sortKeysAndCounts(Grid& grid) {
  HugeVector<uint64_t>& keys = grid.cellKeys;
  HugeVector<uint64_t>& start = grid.cellStart;
  const size_t n = keys.size();
  const int countBits = 64 - std::max(1, int(std::bit_width(grid.cellCount() - 1)));
  uint64_t most = 0;
  for (size_t c = 0; c < n; ++c) most = std::max(most, start[c + 1] - start[c]);
  if (int(std::bit_width(most)) <= countBits) {
    for (size_t c = 0; c < n; ++c) keys[c] = keys[c] << countBits | (start[c + 1] - start[c]);
    std::sort(keys.begin(), keys.end());
    const uint64_t mask = (uint64_t(1) << countBits) - 1;
    for (size_t c = 0; c < n; ++c) {
      start[c + 1] = start[c] + (keys[c] & mask);
      keys[c] >>= countBits;
    }
    return;
  }
  struct KeyCount {
    uint64_t key, count;
  };
  std::vector<KeyCount> pairs(n);
  for (size_t c = 0; c < n; ++c) pairs[c] = {keys[c], start[c + 1] - start[c]};
  std::sort(pairs.begin(), pairs.end(), [](const KeyCount& a, const KeyCount& b) { return a.key < b.key; });
  for (size_t c = 0; c < n; ++c) {
    keys[c] = pairs[c].key;
    start[c + 1] = start[c] + pairs[c].count;
  }
}

// Solid runs sorted and merged where they touch; cells sorted by key (bricks side by side along x or y interleave)
// unless `cells` is BrickOrder, with their primitive lists (Sorted) or only their counts (KeysAndCounts: cellStart
// without primIds), or keys alone (KeysOnly: cellStart emptied).
void sortLayer(Grid& grid, LayerCells cells) {
  std::sort(grid.solidRuns.begin(), grid.solidRuns.end(),
            [](const CellRun& a, const CellRun& b) { return a.first < b.first; });
  std::vector<CellRun> runs;
  runs.reserve(grid.solidRuns.size());
  for (const CellRun& r : grid.solidRuns) appendSolidRun(runs, r);
  grid.solidRuns = std::move(runs);
  if (cells == LayerCells::KeysOnly) {
    std::sort(grid.cellKeys.begin(), grid.cellKeys.end());
    grid.cellStart.clear();
    return;
  }
  if (cells == LayerCells::BrickOrder || std::is_sorted(grid.cellKeys.begin(), grid.cellKeys.end())) return;
  const size_t n = grid.occupiedCount();
  if (cells == LayerCells::KeysAndCounts) return sortKeysAndCounts(grid);
  const bool lists = cells == LayerCells::Sorted;
  std::vector<uint32_t> order(n);
  for (size_t c = 0; c < n; ++c) order[c] = uint32_t(c);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return grid.cellKeys[a] < grid.cellKeys[b]; });
  Grid sorted;
  sorted.cellKeys.reserve(n);
  sorted.cellStart.reserve(n + 1);
  if (lists) sorted.primIds.reserve(grid.primIds.size());
  for (uint32_t c : order) {
    sorted.cellKeys.push_back(grid.cellKeys[c]);
    if (lists) {
      const auto prims = grid.cellPrims(c);
      sorted.primIds.insert(sorted.primIds.end(), prims.begin(), prims.end());
    }
    sorted.cellStart.push_back(sorted.cellStart.back() + (grid.cellStart[c + 1] - grid.cellStart[c]));
  }
  grid.cellKeys = std::move(sorted.cellKeys);
  grid.cellStart = std::move(sorted.cellStart);
  grid.primIds = std::move(sorted.primIds);
}

}  // namespace

void forEachGridSetLayer(const std::string& setPath, const GridSetManifest& m, const GridFile& sceneFile,
                         const std::function<void(const Grid& layer)>& visit, LayerCells cells) {
  size_t i = 0;
  // One grid for every layer: its arrays keep their capacity from layer to layer instead of being allocated and
  // faulted in again (page faults were a fifth of a .vox export's time).
  Grid layer = emptyGridLike(sceneFile.grid);
  for (uint32_t bz = 0; bz < m.bricks[2]; ++bz) {
    layer.cellKeys.clear();
    layer.cellStart.assign(1, 0);
    layer.primIds.clear();
    layer.solidRuns.clear();
    // Sized once from the manifest's counts, not grown by doubling as bricks are appended (up to twice the layer).
    size_t end = i;
    uint64_t occupied = 0, references = 0;
    for (; end < m.entries.size() && m.entries[end].index[2] == bz; ++end) {
      occupied += m.entries[end].occupied;
      references += m.entries[end].references;
    }
    requireListedBricks(setPath, m, i, end);
    layer.cellKeys.reserve(occupied);
    if (cells != LayerCells::KeysOnly) layer.cellStart.reserve(occupied + 1);
    if (cells == LayerCells::Sorted || cells == LayerCells::BrickOrder) layer.primIds.reserve(references);
    for (; i < end; ++i) {
      Grid brick = readBrick(setPath, m, i, sceneFile.scene.boundedCount());
      if (cells == LayerCells::KeysOnly) brick.cellStart = {0};
      if (cells == LayerCells::KeysOnly || cells == LayerCells::KeysAndCounts)
        HugeVector<uint32_t>().swap(brick.primIds);
      appendBrick(layer, brick);
    }
    if (layer.cellKeys.size() > UINT32_MAX) fail<LimitError>(setPath, ": a layer of bricks holds more than 2^32 cells");
    sortLayer(layer, cells);
    visit(layer);
  }
}

GridFile readGridSet(const std::string& path) {
  const GridSetManifest m = readGridSetManifest(path);
  uint64_t occupied = 0, references = 0;
  for (const BrickEntry& e : m.entries) {
    occupied += e.occupied;
    references += e.references;
  }
  checkMemory(double(occupied) * 16 + double(references) * 4 + double(occupied) * 4, path, "the assembled grid");
  if (occupied > UINT32_MAX) fail<LimitError>(path, ": ", occupied, " cells are more than one process assembles");
  requireListedBricks(path, m, 0, m.entries.size());
  GridFile whole = readGridSetScene(path, m);
  Grid& g = whole.grid;
  g.cellKeys.reserve(occupied);
  g.cellStart.reserve(occupied + 1);
  g.primIds.reserve(references);
  for (size_t i = 0; i < m.entries.size(); ++i) appendBrick(g, readBrick(path, m, i, whole.scene.boundedCount()));
  sortLayer(g, LayerCells::Sorted);
  return whole;
}

bool isGridSet(const std::string& path) {
  requireRegularFile(path, "grid file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail<InputError>(path, ": cannot open");
  char magic[8] = {};
  in.read(magic, 8);
  if (in.gcount() == 8 && std::memcmp(magic, kBrickMagic, 8) == 0)
    fail<InputError>(path,
                     ": a brick of a grid set, not a grid: open the set's manifest (NAME.vgrid beside NAME.bricks/)");
  return in.gcount() == 8 && std::memcmp(magic, kSetMagic, 8) == 0;
}

GridFile readGridOrSet(const std::string& path, const std::function<bool(double)>& progress) {
  return isGridSet(path) ? readGridSet(path) : readGridFile(path, progress);
}

}  // namespace vox
