// Brick files of a grid set (docs/grid-format.md "Brick file"): one brick's cells, primitive lists and solid runs,
// with whole-grid keys, naming the set's scene file by name and checksum instead of carrying the scene. Untrusted
// input like a grid file: every count, key, id and run is checked before use.
#include <algorithm>

#include "io/grid_set_header.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"

namespace vox {

namespace {

bool sameVec(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

bool insideWindow(const std::array<uint32_t, 3>& ijk, const CellWindow& w) {
  for (int a = 0; a < 3; ++a)
    if (ijk[a] < w.first[a] || ijk[a] >= w.end[a]) return false;
  return true;
}

// Whether every cell of `run` lies in the window, in O(1): a run crossing a row end covers whole rows between its
// ends, so the window must span x whole, and y whole too when the run crosses a z layer.
bool runInsideWindow(const CellRun& run, const std::array<uint32_t, 3>& dims, const CellWindow& w) {
  const uint64_t last = run.first + run.count - 1;
  const auto a = cellIndex(dims, run.first), b = cellIndex(dims, last);
  if (!insideWindow(a, w) || !insideWindow(b, w)) return false;
  if (run.first / dims[0] == last / dims[0]) return true;
  if (w.first[0] != 0 || w.end[0] != dims[0]) return false;
  return a[2] == b[2] || (w.first[1] == 0 && w.end[1] == dims[1]);
}

// The cell table: keys strictly ascending inside the window, offsets partitioning the references, ids ascending
// per cell and below `bounded`.
void checkCells(const Grid& g, const CellWindow& w, uint64_t bounded, const std::string& name, size_t at) {
  auto bad = [&](const std::string& what) { fail<InputError>(name, ": cell table at byte ", at, ": ", what); };
  for (size_t c = 0; c < g.cellKeys.size(); ++c) {
    if (g.cellKeys[c] >= g.cellCount() || (c > 0 && g.cellKeys[c] <= g.cellKeys[c - 1]))
      bad("cell keys not sorted or outside the grid");
    const auto ijk = cellIndex(g.dims, g.cellKeys[c]);
    if (!insideWindow(ijk, w))
      bad("cell (" + std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " + std::to_string(ijk[2]) +
          ") outside its brick");
  }
  if (g.cellStart.size() != g.cellKeys.size() + 1) bad("cell offsets do not match the cell count");
  if (g.cellStart.front() != 0 || g.cellStart.back() != g.primIds.size())
    bad("cell offsets do not cover the references");
  for (size_t c = 0; c + 1 < g.cellStart.size(); ++c)
    if (g.cellStart[c + 1] <= g.cellStart[c] || g.cellStart[c + 1] > g.primIds.size())
      bad("cell " + std::to_string(c) + ": offsets empty, backwards or past the references");
  for (size_t c = 0; c + 1 < g.cellStart.size(); ++c)
    for (uint64_t k = g.cellStart[c]; k < g.cellStart[c + 1]; ++k)
      if (g.primIds[k] >= bounded || (k > g.cellStart[c] && g.primIds[k] <= g.primIds[k - 1]))
        bad("primitive ids not ascending or out of range");
}

}  // namespace

std::string encodeBrickFile(const GridSetManifest& set, const std::array<uint32_t, 3>& index, const Grid& cells) {
  ByteWriter w;
  w.putString(set.scene.file);
  w.put(set.scene.checksum);
  w.putVec(set.bounds.lo);
  w.putVec(set.bounds.hi);
  for (uint32_t n : set.dims) w.put(n);
  w.put(uint8_t(set.method));
  for (uint32_t b : set.bricks) w.put(b);
  for (uint32_t i : index) w.put(i);
  w.putArray(cells.cellKeys);
  w.putArray(cells.cellStart);
  w.putArray(cells.primIds);
  w.putArray(cells.solidRuns);
  return withSetHeader(kBrickMagic, kBrickFileVersion, w.bytes());
}

Grid decodeBrickFile(const std::string& bytes, const std::string& name, const GridSetManifest& set,
                     const BrickEntry& entry, uint64_t boundedCount) {
  checkSetHeader(bytes, name, kBrickMagic, kBrickFileVersion, "grid-set brick file");
  ByteReader r(bytes, kSetHeaderSize, name);
  const std::string scene = r.getString();
  if (scene != set.scene.file || r.get<uint64_t>() != set.scene.checksum)
    fail<InputError>(name, ": belongs to another scene file (", quoteInput(scene), ") than its manifest's (",
                     quoteInput(set.scene.file), " of checksum ", set.scene.checksum, ")");
  Grid g;
  g.bounds.lo = r.getVec("bounds");
  g.bounds.hi = r.getVec("bounds");
  for (uint32_t& n : g.dims) n = r.get<uint32_t>();
  const uint8_t method = r.get<uint8_t>();
  std::array<uint32_t, 3> bricks{}, index{};
  for (uint32_t& b : bricks) b = r.get<uint32_t>();
  for (uint32_t& i : index) i = r.get<uint32_t>();
  if (!sameVec(g.bounds.lo, set.bounds.lo) || !sameVec(g.bounds.hi, set.bounds.hi) || g.dims != set.dims ||
      method != uint8_t(set.method) || bricks != set.bricks)
    fail<InputError>(name, ": bounds, dims, method or bricks differ from its manifest's");
  if (index != entry.index) fail<InputError>(name, ": holds another brick than its manifest lists there");
  g.method = set.method;
  const size_t cellsAt = r.position();
  g.cellKeys = r.getArray<uint64_t, HugeVector<uint64_t>>("cell");
  g.cellStart = r.getArray<uint64_t, HugeVector<uint64_t>>("cell start");
  g.primIds = r.getArray<uint32_t, HugeVector<uint32_t>>("reference");
  const size_t runsAt = r.position();
  g.solidRuns = r.getArray<CellRun>("solid run");
  if (!r.atEnd()) r.corrupt("trailing bytes after the solid runs");
  const CellWindow w = brickWindow(set.dims, set.bricks, index);
  checkCells(g, w, boundedCount, name, cellsAt);
  checkSolidRuns(g.solidRuns, g.cellCount(), name + ": solid runs at byte " + std::to_string(runsAt));
  checkSolidRunsMissCells(g.cellKeys, g.solidRuns, name + ": solid runs at byte " + std::to_string(runsAt));
  for (const CellRun& run : g.solidRuns)
    if (!runInsideWindow(run, g.dims, w))
      fail<InputError>(name, ": solid runs at byte ", runsAt, ": a run outside its brick");
  if (g.occupiedCount() != entry.occupied || g.referenceCount() != entry.references || g.solidCount() != entry.solid)
    fail<InputError>(name, ": cell, reference or solid count differs from its manifest's");
  return g;
}

}  // namespace vox
