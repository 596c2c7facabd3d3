// --fill over a grid set (fillGridSet): the single grid's fill, decided slab by slab (SlabFill) from the bricks' cell
// keys, in memory bounded by a layer of bricks' keys delta-coded, one brick and one slab rather than the grid.
#include "vox/sets/fill_set.h"

#include <algorithm>
#include <cstring>
#include <span>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/varint.h"

namespace vox {

namespace {

// The varint at bytes[pos] (vox/core/varint.h); pos moves past it. Only our own bytes are read.
uint64_t readVarint(const std::vector<uint8_t>& bytes, size_t& pos) {
  const uint8_t* p = bytes.data() + pos;
  uint64_t v = 0;
  VOX_CHECK(getVarint(p, bytes.data() + bytes.size(), v) == VarintStatus::Ok);
  pos = size_t(p - bytes.data());
  return v;
}

// The sorted keys of one brick, delta-coded: a run of cells along x costs a byte a cell, a step to the next row two
// or three, instead of 8 bytes a key. Read back in order, up to a key bound at a time.
struct PackedKeys {
  std::vector<uint8_t> bytes;
  size_t pos = 0;     // read cursor into bytes
  uint64_t last = 0;  // the last key read

  explicit PackedKeys(std::span<const uint64_t> keys) {
    bytes.reserve(keys.size() + keys.size() / 4);
    uint64_t previous = 0;
    for (const uint64_t key : keys) appendVarint(bytes, key - previous), previous = key;
  }
  // Appends to `out` the keys not read yet that lie below `end`.
  void readBelow(uint64_t end, std::vector<uint64_t>& out) {
    while (pos < bytes.size()) {
      size_t p = pos;
      const uint64_t key = last + readVarint(bytes, p);
      if (key >= end) return;
      last = key, pos = p;
      out.push_back(key);
    }
  }
};

// The solid runs of one brick as they come, ascending, merged where they touch and delta-coded (gap from the previous
// run's end, count: a few bytes a run instead of 16). A layer's runs are what the fill holds longest.
struct PackedRuns {
  std::vector<uint8_t> bytes;
  CellRun pending{0, 0};  // the last run, which the next may extend
  uint64_t end = 0;       // the end of the last run packed

  void add(const CellRun& run) {
    if (pending.count > 0 && pending.first + pending.count == run.first) {
      pending.count += run.count;
      return;
    }
    flush();
    pending = run;
  }
  void flush() {
    if (pending.count == 0) return;
    appendVarint(bytes, pending.first - end);
    appendVarint(bytes, pending.count);
    end = pending.first + pending.count;
    pending = {0, 0};
  }
  std::vector<CellRun> unpack() {
    flush();
    std::vector<CellRun> runs;
    uint64_t at = 0;
    for (size_t pos = 0; pos < bytes.size();) {
      const uint64_t first = at + readVarint(bytes, pos), count = readVarint(bytes, pos);
      runs.push_back({first, count});
      at = first + count;
    }
    return runs;
  }
};

// One layer of bricks (all with one bz) as SlabFill reads it: each brick's keys packed, and the cells per plane.
struct PackedLayer {
  uint32_t firstPlane = 0, endPlane = 0;
  std::vector<PackedKeys> bricks;
  std::vector<uint64_t> cellsPerPlane;  // plane firstPlane + p holds cellsPerPlane[p] occupied cells
};

// Reads the bricks of layer `bz`, entries [first, end) of the manifest.
PackedLayer readPackedLayer(const std::string& setPath, const GridSetManifest& set, uint32_t bz, size_t first,
                            size_t end, uint64_t boundedCount) {
  PackedLayer layer;
  const CellWindow window = brickWindow(set.dims, set.bricks, {0, 0, bz});
  layer.firstPlane = window.first[2], layer.endPlane = window.end[2];
  layer.cellsPerPlane.assign(layer.endPlane - layer.firstPlane, 0);
  const uint64_t plane = uint64_t(set.dims[0]) * set.dims[1];
  for (size_t i = first; i < end; ++i) {
    const Grid brick = readBrick(setPath, set, i, boundedCount);  // keys checked inside the brick, sorted
    for (const uint64_t key : brick.cellKeys) ++layer.cellsPerPlane[key / plane - layer.firstPlane];
    layer.bricks.emplace_back(brick.cellKeys);
  }
  return layer;
}

// Calls slab(keys, k0, k1) for consecutive slabs of whole planes of every layer, bottom to top, each holding at most
// `slabCells` cells unless one plane holds more, and layerDone(bz) after each layer's slabs.
template <typename Slab, typename LayerDone>
void forEachSlab(const std::string& setPath, const GridSetManifest& set, uint64_t boundedCount, uint64_t slabCells,
                 const Slab& slab, const LayerDone& layerDone) {
  const uint64_t plane = uint64_t(set.dims[0]) * set.dims[1];
  std::vector<uint64_t> keys;
  size_t first = 0;
  for (uint32_t bz = 0; bz < set.bricks[2]; ++bz) {
    size_t end = first;
    while (end < set.entries.size() && set.entries[end].index[2] == bz) ++end;
    PackedLayer layer = readPackedLayer(setPath, set, bz, first, end, boundedCount);
    first = end;
    for (uint32_t k0 = layer.firstPlane; k0 < layer.endPlane;) {
      uint32_t k1 = k0 + 1;
      uint64_t cells = layer.cellsPerPlane[k0 - layer.firstPlane];
      while (k1 < layer.endPlane && cells + layer.cellsPerPlane[k1 - layer.firstPlane] <= slabCells)
        cells += layer.cellsPerPlane[k1++ - layer.firstPlane];
      keys.clear();
      keys.reserve(cells);
      // A row crosses the bricks of its layer along x, so the bricks' keys interleave row by row.
      for (PackedKeys& brick : layer.bricks) brick.readBelow(k1 * plane, keys);
      std::sort(keys.begin(), keys.end());
      slab(std::span<const uint64_t>(keys), k0, k1);
      k0 = k1;
    }
    layerDone(bz);
  }
}

// The solid runs of one layer of bricks, split by brick as they come (slab by slab, ascending): no copy of the
// layer's runs is held beside them.
struct LayerRuns {
  std::vector<PackedRuns> byBrick;  // brick bx + BX by of the layer

  void add(const GridSetManifest& set, std::span<const CellRun> runs) {
    byBrick.resize(uint64_t(set.bricks[0]) * set.bricks[1]);
    for (auto& [number, brickRuns] : splitRunsByBrick(runs, set.dims, set.bricks)) {
      const auto index = brickIndex(set.bricks, number);
      for (const CellRun& run : brickRuns) byBrick[index[0] + uint64_t(set.bricks[0]) * index[1]].add(run);
    }
  }
  // Writes the bricks of layer `bz` holding solid runs: each existing brick rewritten with its runs, a new one for a
  // brick holding only solid cells. Appends their entries to `written`, ascending by brick number, and empties the
  // layer.
  void write(const std::string& setPath, const GridSetManifest& set, uint32_t bz, uint64_t boundedCount,
             std::vector<BrickEntry>& written) {
    for (uint64_t b = 0; b < byBrick.size(); ++b) {
      if (byBrick[b].bytes.empty() && byBrick[b].pending.count == 0) continue;
      const std::array<uint32_t, 3> index{uint32_t(b % set.bricks[0]), uint32_t(b / set.bricks[0]), bz};
      const uint64_t number = brickNumber(set.bricks, index);
      const auto e = std::lower_bound(
          set.entries.begin(), set.entries.end(), number,
          [&](const BrickEntry& entry, uint64_t n) { return brickNumber(set.bricks, entry.index) < n; });
      Grid cells = emptyGridLike(set);
      if (e != set.entries.end() && brickNumber(set.bricks, e->index) == number)
        cells = readBrick(setPath, set, size_t(e - set.entries.begin()), boundedCount);
      cells.solidRuns = byBrick[b].unpack();
      byBrick[b] = {};
      written.push_back(writeBrickFile(setPath, set, index, cells));
    }
  }
};

// `entries` with the `written` ones in place of those of the same brick (both ascending by brick number).
std::vector<BrickEntry> mergeEntries(const GridSetManifest& set, const std::vector<BrickEntry>& written) {
  std::vector<BrickEntry> entries;
  entries.reserve(set.entries.size() + written.size());
  auto number = [&](const BrickEntry& e) { return brickNumber(set.bricks, e.index); };
  size_t w = 0;
  for (const BrickEntry& e : set.entries) {
    while (w < written.size() && number(written[w]) < number(e)) entries.push_back(written[w++]);
    if (w < written.size() && number(written[w]) == number(e))
      entries.push_back(written[w++]);
    else
      entries.push_back(e);
  }
  entries.insert(entries.end(), written.begin() + ptrdiff_t(w), written.end());
  return entries;
}

}  // namespace

FillReport fillGridSet(const std::string& setPath, GridSetManifest& set, const Scene& scene,
                       const FillOptions& options) {
  const uint64_t boundedCount = scene.boundedCount();
  SlabFill fill(emptyGridLike(set), scene, options);
  forEachSlab(
      setPath, set, boundedCount, options.slabCells,
      [&](std::span<const uint64_t> keys, uint32_t k0, uint32_t k1) { fill.link(keys, k0, k1); }, [](uint32_t) {});
  // The second reading decides each layer's runs; its bricks are rewritten once the layer is done.
  std::vector<BrickEntry> written;
  LayerRuns runs;
  forEachSlab(
      setPath, set, boundedCount, options.slabCells,
      [&](std::span<const uint64_t> keys, uint32_t k0, uint32_t k1) { runs.add(set, fill.fill(keys, k0, k1)); },
      [&](uint32_t bz) { runs.write(setPath, set, bz, boundedCount, written); });
  set.entries = mergeEntries(set, written);
  return fill.report();
}

}  // namespace vox
