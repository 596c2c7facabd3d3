// Grid-set manifests and reading a set back (docs/grid-format.md "Grid sets"). The manifest is untrusted input like
// a grid file: every count, index and name is checked, and a brick must lie inside the manifest's folder.
#include "vox/io/grid_set.h"

#include <algorithm>
#include <cstring>
#include <fstream>

#include "io/byte_codec.h"
#include "vox/core/error.h"
#include "vox/io/input_file.h"

namespace vox {

namespace {

constexpr char kSetMagic[8] = {'V', 'O', 'X', 'G', 'S', 'E', 'T', '\n'};
constexpr size_t kHeaderSize = 32;  // magic, version, flags, payload size, checksum (as the grid file)
constexpr size_t kGridChecksumOffset = 24;

uint64_t headerChecksum(const std::string& fileBytes) {
  uint64_t c = 0;
  if (fileBytes.size() >= kHeaderSize) std::memcpy(&c, fileBytes.data() + kGridChecksumOffset, 8);
  return c;
}

void putEntry(ByteWriter& w, const BrickEntry& e) {
  for (uint32_t i : e.index) w.put(i);
  w.putString(e.file);
  w.put(e.fileSize);
  w.put(e.fileChecksum);
  w.put(e.occupied);
  w.put(e.references);
}

BrickEntry getEntry(ByteReader& r) {
  BrickEntry e;
  for (uint32_t& i : e.index) i = r.get<uint32_t>();
  e.file = r.getString();
  e.fileSize = r.get<uint64_t>();
  e.fileChecksum = r.get<uint64_t>();
  e.occupied = r.get<uint64_t>();
  e.references = r.get<uint64_t>();
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

// Entries in strictly ascending brick order, named by relative paths, counts adding up to the totals.
void checkEntries(ByteReader& r, const GridSetManifest& m, uint64_t occupied, uint64_t references) {
  uint64_t sumOccupied = 0, sumReferences = 0;
  for (size_t i = 0; i < m.entries.size(); ++i) {
    const BrickEntry& e = m.entries[i];
    for (int a = 0; a < 3; ++a)
      if (e.index[a] >= m.bricks[a]) r.corrupt("brick " + std::to_string(i) + ": index out of range");
    if (i > 0 && brickNumber(m.bricks, e.index) <= brickNumber(m.bricks, m.entries[i - 1].index))
      r.corrupt("bricks not in ascending order");
    if (e.file.empty() || e.file.find('\0') != std::string::npos)
      r.corrupt("brick " + std::to_string(i) + ": bad file name");
    if (e.occupied == 0 && m.entries.size() > 1) r.corrupt("brick " + std::to_string(i) + ": empty brick listed");
    if (e.references < e.occupied) r.corrupt("brick " + std::to_string(i) + ": fewer references than cells");
    sumOccupied += e.occupied;
    sumReferences += e.references;
    if (sumOccupied < e.occupied || sumReferences < e.references) r.corrupt("cell counts overflow");
  }
  if (m.entries.empty()) r.corrupt("a set names at least one brick (it carries the scene)");
  if (sumOccupied != occupied || sumReferences != references) r.corrupt("brick counts do not add up to the totals");
}

}  // namespace

std::string encodeGridSetManifest(const GridSetManifest& m) {
  ByteWriter w;
  w.putVec(m.bounds.lo);
  w.putVec(m.bounds.hi);
  for (uint32_t n : m.dims) w.put(n);
  w.put(uint8_t(m.method));
  for (uint32_t b : m.bricks) w.put(b);
  uint64_t occupied = 0, references = 0;
  for (const BrickEntry& e : m.entries) {
    occupied += e.occupied;
    references += e.references;
  }
  w.put(occupied);
  w.put(references);
  w.put(uint64_t(m.entries.size()));
  for (const BrickEntry& e : m.entries) putEntry(w, e);
  const std::string& payload = w.bytes();
  ByteWriter h;
  h.bytes().append(kSetMagic, 8);
  h.put(kGridSetVersion);
  h.put(uint32_t(0));
  h.put(uint64_t(payload.size()));
  h.put(gridChecksum(payload.data(), payload.size()));
  return h.bytes() + payload;
}

GridSetManifest decodeGridSetManifest(const std::string& bytes, const std::string& name) {
  ByteReader r(bytes, 0, name);
  r.need(kHeaderSize);
  if (std::memcmp(bytes.data(), kSetMagic, 8) != 0) r.corrupt("not a grid-set manifest (bad magic)");
  ByteReader h(bytes, 8, name);
  const uint32_t version = h.get<uint32_t>();
  if (version == 0 || version > kGridSetVersion)
    h.corrupt("manifest version " + std::to_string(version) + " (this reader knows 1 to " +
              std::to_string(kGridSetVersion) + ")");
  if (h.get<uint32_t>() != 0) h.corrupt("unknown flags");
  const uint64_t size = h.get<uint64_t>();
  if (size != bytes.size() - kHeaderSize) {
    if (size > bytes.size() - kHeaderSize)
      fail<InputError>(name, ": truncated at byte ", bytes.size(), " (header promises ", kHeaderSize + size,
                       " bytes)");
    h.corrupt("payload size " + std::to_string(size) + " does not match the file");
  }
  if (h.get<uint64_t>() != gridChecksum(bytes.data() + kHeaderSize, size)) h.corrupt("checksum mismatch");
  GridSetManifest m;
  ByteReader p(bytes, kHeaderSize, name);
  getPlan(p, m);
  const uint64_t occupied = p.get<uint64_t>();
  const uint64_t references = p.get<uint64_t>();
  // The smallest entry is 3 u32, an empty name's u32 and 4 u64.
  const uint64_t count = p.getCount(48, "brick");
  m.entries.reserve(count);
  for (uint64_t i = 0; i < count; ++i) m.entries.push_back(getEntry(p));
  if (!p.atEnd()) p.corrupt("trailing bytes after the bricks");
  checkEntries(p, m, occupied, references);
  return m;
}

GridSetManifest readGridSetManifest(const std::string& path) {
  return decodeGridSetManifest(readInputFile(path, "grid-set manifest"), path);
}

GridFile readBrick(const std::string& setPath, const GridSetManifest& m, size_t entry) {
  VOX_CHECK(entry < m.entries.size());
  const BrickEntry& e = m.entries[entry];
  // Refuses absolute names and names leaving the manifest's folder (after "..", symbolic links included).
  const std::string path = resolveInsideFolder(setPath, e.file);
  const std::string bytes = readInputFile(path, "brick file");
  if (bytes.size() != e.fileSize || headerChecksum(bytes) != e.fileChecksum)
    fail<InputError>(path, ": not the brick ", setPath, " names (size or checksum differ; rewritten since?)");
  GridFile brick = decodeGridFile(bytes, path);
  const Grid& g = brick.grid;
  auto same = [](const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  if (!same(g.bounds.lo, m.bounds.lo) || !same(g.bounds.hi, m.bounds.hi) || g.dims != m.dims || g.method != m.method)
    fail<InputError>(path, ": bounds, dims or method differ from its manifest ", setPath);
  if (g.occupiedCount() != e.occupied || g.referenceCount() != e.references)
    fail<InputError>(path, ": cell or reference count differs from its manifest ", setPath);
  const CellWindow w = brickWindow(m.dims, m.bricks, e.index);
  for (uint64_t key : g.cellKeys) {
    const auto ijk = cellIndex(g.dims, key);
    for (int a = 0; a < 3; ++a)
      if (ijk[a] < w.first[a] || ijk[a] >= w.end[a])
        fail<InputError>(path, ": cell (", ijk[0], ", ", ijk[1], ", ", ijk[2], ") outside its brick");
  }
  if (!g.solidRuns.empty()) fail<InputError>(path, ": a brick holds no solid cells");
  return brick;
}

namespace {

// Appends a brick's cells to the whole grid. Bricks are disjoint boxes, so the merged keys are the union; they are
// sorted once at the end when the bricks interleave (any brick count above one along x or y).
void appendBrick(Grid& whole, const Grid& brick) {
  for (size_t c = 0; c < brick.occupiedCount(); ++c) {
    whole.cellKeys.push_back(brick.cellKeys[c]);
    const auto prims = brick.cellPrims(c);
    whole.primIds.insert(whole.primIds.end(), prims.begin(), prims.end());
    whole.cellStart.push_back(whole.primIds.size());
  }
}

void sortCells(Grid& grid) {
  const size_t n = grid.occupiedCount();
  std::vector<uint32_t> order(n);
  for (size_t c = 0; c < n; ++c) order[c] = uint32_t(c);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return grid.cellKeys[a] < grid.cellKeys[b]; });
  Grid sorted;
  sorted.cellKeys.reserve(n);
  sorted.cellStart.reserve(n + 1);
  sorted.primIds.reserve(grid.primIds.size());
  for (uint32_t c : order) {
    sorted.cellKeys.push_back(grid.cellKeys[c]);
    const auto prims = grid.cellPrims(c);
    sorted.primIds.insert(sorted.primIds.end(), prims.begin(), prims.end());
    sorted.cellStart.push_back(sorted.primIds.size());
  }
  grid.cellKeys = std::move(sorted.cellKeys);
  grid.cellStart = std::move(sorted.cellStart);
  grid.primIds = std::move(sorted.primIds);
}

}  // namespace

GridFile readGridSet(const std::string& path) {
  const GridSetManifest m = readGridSetManifest(path);
  uint64_t occupied = 0, references = 0;
  for (const BrickEntry& e : m.entries) {
    occupied += e.occupied;
    references += e.references;
  }
  checkMemory(double(occupied) * 16 + double(references) * 4 + double(occupied) * 4, path, "the assembled grid");
  if (occupied > UINT32_MAX) fail<LimitError>(path, ": ", occupied, " cells are more than one process assembles");
  GridFile whole;
  for (size_t i = 0; i < m.entries.size(); ++i) {
    GridFile brick = readBrick(path, m, i);
    if (i == 0) {
      whole.scene = std::move(brick.scene);
      whole.grid = brick.grid;
      whole.grid.cellKeys.clear();
      whole.grid.cellStart.assign(1, 0);
      whole.grid.primIds.clear();
      whole.grid.cellKeys.reserve(occupied);
      whole.grid.cellStart.reserve(occupied + 1);
      whole.grid.primIds.reserve(references);
    } else if (brick.scene.triangles.size() != whole.scene.triangles.size() ||
               brick.scene.spheres.size() != whole.scene.spheres.size() ||
               brick.scene.planes.size() != whole.scene.planes.size() ||
               brick.grid.outsidePrims != whole.grid.outsidePrims) {
      fail<InputError>(resolveInsideFolder(path, m.entries[i].file), ": its scene differs from the set's first brick");
    }
    appendBrick(whole.grid, brick.grid);
  }
  if (!std::is_sorted(whole.grid.cellKeys.begin(), whole.grid.cellKeys.end())) sortCells(whole.grid);
  return whole;
}

bool isGridSet(const std::string& path) {
  requireRegularFile(path, "grid file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail<InputError>(path, ": cannot open");
  char magic[8] = {};
  in.read(magic, 8);
  return in.gcount() == 8 && std::memcmp(magic, kSetMagic, 8) == 0;
}

GridFile readGridOrSet(const std::string& path) { return isGridSet(path) ? readGridSet(path) : readGridFile(path); }

}  // namespace vox
