// MagicaVoxel writer (magicavoxel_writer.h). Two passes over the voxel rows of the grid's pieces (the whole grid in
// memory, or a grid set's layers of bricks): the first counts the voxels of every 256^3 tile (chunk sizes come
// before their content, and MAIN's size before everything) and of every colour (the palette comes from all of
// them), the second buffers one 256-thick z slab of tiles at a time and writes their SIZE and XYZI chunks. Keys with
// k in one slab are one contiguous key range, so the slab is complete when the rows move past it, whatever the
// pieces' thickness.
#include "vox/export/magicavoxel_writer.h"

#include <algorithm>
#include <bit>
#include <array>
#include <climits>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>

#include "export/export_budget.h"
#include "vox/core/checked_math.h"
#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"

namespace vox {

// XYZI voxels are written straight from packed words.
static_assert(std::endian::native == std::endian::little);

namespace {

uint32_t pack(const Rgb8& c) { return c[0] | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16); }
Rgb8 unpack(uint32_t c) { return {uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)}; }

void putU32(std::string& s, uint32_t v) {
  for (int b = 0; b < 4; ++b) s.push_back(char(uint8_t(v >> (8 * b))));
}
void putString(std::string& s, const std::string& v) {
  putU32(s, uint32_t(v.size()));
  s += v;
}
void putChunkHeader(std::string& s, const char* id, uint64_t content, uint64_t children) {
  s.append(id, 4);
  putU32(s, uint32_t(content));
  putU32(s, uint32_t(children));
}
void putChunk(std::string& s, const char* id, const std::string& content) {
  putChunkHeader(s, id, content.size(), 0);
  s += content;
}

struct Tile {
  std::array<uint32_t, 3> origin;  // in cells
  std::array<uint32_t, 3> size;
  uint64_t voxels = 0;
};

struct Tiling {
  uint64_t tx, ty;  // tiles along x and y
  uint64_t key(uint64_t i, uint64_t j, uint64_t k) const {
    return i / kVoxModelSide + tx * (j / kVoxModelSide + ty * (k / kVoxModelSide));
  }
};

// Calls piece(tileKey, i0, count) for the parts of a voxel row that fall in different tiles.
template <typename F>
void splitRow(const Tiling& tiling, const VoxelRow& r, F&& piece) {
  uint32_t i = r.i0;
  const uint32_t end = r.i0 + r.count;
  while (i < end) {
    const uint32_t stop = std::min<uint32_t>(end, (i / kVoxModelSide + 1) * kVoxModelSide);
    piece(tiling.key(i, r.j, r.k), i, stop - i);
    i = stop;
  }
}

// Calls onPiece(piece, colours) for every piece in order, then onRow(row) for each of its voxel rows; refuses colours
// of the wrong count, and keys that do not ascend from one piece to the next (forEachVoxelRow checks them within).
template <typename P, typename R>
void forEachPieceRow(const ColoredPieceSource& pieces, P&& onPiece, R&& onRow) {
  uint64_t next = 0;  // smallest key the next row may start at
  pieces([&](const Grid& piece, std::span<const Rgb8> colors) {
    if (!colors.empty() && colors.size() != piece.cellKeys.size())
      fail<InputError>("vox: ", colors.size(), " cell colours for ", piece.cellKeys.size(), " occupied cells");
    onPiece(piece, colors);
    forEachVoxelRow(piece, [&](const VoxelRow& r) {
      if (r.key < next)
        fail<InputError>("vox: cell key ", r.key, " repeated or out of order between pieces of the grid");
      next = r.key + r.count;
      onRow(r);
    });
  });
}

// What the file's layout and palette need before anything is written: the voxels of every non-empty tile, and the
// voxels of every colour (occupied cells by their colour, the rest by solidColor).
struct Census {
  std::map<uint64_t, Tile> tiles;
  std::unordered_map<uint32_t, uint64_t> weights;
  uint64_t voxels = 0;
  uint64_t solidOnly = 0;  // voxels without a cell colour
};

// The fewest bytes a file with `voxels` voxels in `models` models can take: 4 per voxel (XYZI), and per model its
// SIZE (24) and XYZI (16) chunk headers, its nTRN (55 with the shortest "_t") and nSHP (32) chunks and its id in the
// nGRP's child list (4). Refusing on this bound, before a row is visited, keeps the census (one map entry per model)
// and the rows it visits bounded by the format's 2^31 - 1 bytes.
constexpr uint64_t kMinModelBytes = 24 + 16 + 55 + 32 + 4;
// A Tile in the census's std::map: the value and the map node's pointers, colour and allocator header.
constexpr uint64_t kCensusTileBytes = sizeof(std::pair<const uint64_t, Tile>) + 48;

uint64_t minFileBytes(uint64_t voxels, uint64_t models) {
  return saturatingSum({saturatingMul(4, voxels), saturatingMul(kMinModelBytes, models)});
}

[[noreturn]] void refuseFileSize(uint64_t voxels, uint64_t bytes) {
  fail<LimitError>("vox: ", describeCount(voxels), " voxels need ",
                   bytes == UINT64_MAX ? "2^64 bytes or more" : "at least " + describeCount(bytes) + " bytes",
                   ", more than the 2^31 - 1 that the format's int32 chunk sizes allow (export a coarser grid or "
                   "several bricks)");
}

Census takeCensus(const Grid& plan, const Tiling& tiling, const ColoredPieceSource& pieces, Rgb8 solidColor) {
  Census census;
  uint64_t colored = 0;
  uint64_t tallied = 0;  // voxels of the pieces reached so far, counted from their runs before their rows
  const auto weigh = [&](const Grid& piece, std::span<const Rgb8> colors) {
    tallied = saturatingAdd(tallied, tallyVoxels(piece).voxels);
    if (minFileBytes(tallied, 0) > uint64_t(INT32_MAX)) refuseFileSize(tallied, minFileBytes(tallied, 0));
    for (const Rgb8& c : colors) ++census.weights[pack(c)];
    colored += colors.size();
  };
  forEachPieceRow(pieces, weigh, [&](const VoxelRow& r) {
    census.voxels += r.count;
    splitRow(tiling, r, [&](uint64_t key, uint32_t i, uint32_t n) {
      Tile& t = census.tiles[key];
      if (t.voxels == 0) {
        const uint64_t models = census.tiles.size();
        if (minFileBytes(tallied, models) > uint64_t(INT32_MAX)) refuseFileSize(tallied, minFileBytes(tallied, models));
        if (models % 4096 == 0) requireMemory(models * kCensusTileBytes, "vox", "the models' census");
        const std::array<uint32_t, 3> cell{i, r.j, r.k};
        for (int a = 0; a < 3; ++a) {
          t.origin[a] = cell[a] / kVoxModelSide * kVoxModelSide;
          t.size[a] = std::min(kVoxModelSide, plan.dims[a] - t.origin[a]);
        }
      }
      t.voxels += n;
    });
  });
  census.solidOnly = census.voxels - colored;
  if (census.solidOnly > 0) census.weights[pack(solidColor)] += census.solidOnly;
  return census;
}

std::string dict(const std::vector<std::pair<std::string, std::string>>& entries) {
  std::string s;
  putU32(s, uint32_t(entries.size()));
  for (const auto& [k, v] : entries) {
    putString(s, k);
    putString(s, v);
  }
  return s;
}

// Root transform 0 -> group 1 -> per model m: transform 2 + 2m -> shape 3 + 2m (model m).
std::string sceneGraph(const std::map<uint64_t, Tile>& tiles) {
  std::string out, c;
  auto transform = [&](uint32_t id, uint32_t child, int32_t layer, const std::string& frame) {
    c.clear();
    putU32(c, id);
    c += dict({});
    putU32(c, child);
    putU32(c, uint32_t(-1));  // reserved
    putU32(c, uint32_t(layer));
    putU32(c, 1);  // frames
    c += frame;
    putChunk(out, "nTRN", c);
  };
  transform(0, 1, -1, dict({}));
  c.clear();
  putU32(c, 1);
  c += dict({});
  putU32(c, uint32_t(tiles.size()));
  for (uint32_t m = 0; m < tiles.size(); ++m) putU32(c, 2 + 2 * m);
  putChunk(out, "nGRP", c);
  uint32_t m = 0;
  for (const auto& [key, t] : tiles) {
    std::string translation;
    for (int a = 0; a < 3; ++a) {
      if (a) translation.push_back(' ');
      translation.append(std::to_string(uint64_t(t.origin[a]) + t.size[a] / 2));
    }
    transform(2 + 2 * m, 3 + 2 * m, 0, dict({{"_t", translation}}));
    c.clear();
    putU32(c, 3 + 2 * m);
    c += dict({});
    putU32(c, 1);  // models
    putU32(c, m);
    c += dict({});
    putChunk(out, "nSHP", c);
    ++m;
  }
  return out;
}

// Palette index (1..255) of each distinct colour, and the palette itself.
struct PaletteMap {
  std::vector<Rgb8> palette;
  std::unordered_map<uint32_t, uint8_t> index;
};

PaletteMap buildPalette(const std::unordered_map<uint32_t, uint64_t>& weights) {
  std::vector<Rgb8> colors;
  std::vector<uint64_t> w;
  for (const auto& [c, n] : weights) {
    colors.push_back(unpack(c));
    w.push_back(n);
  }
  PaletteMap map;
  map.palette = choosePalette(colors, w);
  for (const Rgb8& c : colors) {
    int best = 0, bestDist = INT_MAX;
    for (size_t p = 0; p < map.palette.size(); ++p) {
      int d = 0;
      for (int ch = 0; ch < 3; ++ch) d += (int(c[ch]) - map.palette[p][ch]) * (int(c[ch]) - map.palette[p][ch]);
      if (d < bestDist) bestDist = d, best = int(p);
    }
    map.index[pack(c)] = uint8_t(best + 1);
  }
  return map;
}

// The second pass: the pieces' voxels, one 256-thick z slab of tiles at a time, as each tile's SIZE and XYZI chunks
// (`buf` holds what precedes the first chunk and is written with it).
void writeModels(std::ostream& out, std::string& buf, const Grid& plan, const Tiling& tiling,
                 const std::map<uint64_t, Tile>& tiles, const ColoredPieceSource& pieces, const PaletteMap& palette,
                 uint8_t solidIndex, const std::function<void(double)>& progress) {
  std::unordered_map<uint64_t, std::vector<uint32_t>> slab;  // tile key -> packed x | y << 8 | z << 16 | i << 24
  int64_t slabZ = -1;
  auto flushSlab = [&] {
    for (auto it = tiles.lower_bound(tiling.key(0, 0, uint64_t(slabZ)));
         it != tiles.end() && int64_t(it->second.origin[2]) == slabZ; ++it) {
      const Tile& t = it->second;
      const std::vector<uint32_t>& v = slab[it->first];
      VOX_CHECK(v.size() == t.voxels);
      putChunkHeader(buf, "SIZE", 12, 0);
      for (int a = 0; a < 3; ++a) putU32(buf, t.size[a]);
      putChunkHeader(buf, "XYZI", 4 + 4 * v.size(), 0);
      putU32(buf, uint32_t(v.size()));
      out.write(buf.data(), std::streamsize(buf.size()));
      buf.clear();
      out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(4 * v.size()));  // little-endian host
    }
    slab.clear();
  };
  // The palette index of each occupied cell of the current piece, and the cell the rows have reached.
  const HugeVector<uint64_t>* keys = nullptr;
  std::vector<uint8_t> cellIndex;
  size_t a = 0;
  const auto startPiece = [&](const Grid& piece, std::span<const Rgb8> colors) {
    keys = &piece.cellKeys;
    cellIndex.resize(colors.size());
    for (size_t c = 0; c < colors.size(); ++c) cellIndex[c] = palette.index.at(pack(colors[c]));
    a = 0;
  };
  forEachPieceRow(pieces, startPiece, [&](const VoxelRow& r) {
    const int64_t z0 = r.k / kVoxModelSide * kVoxModelSide;
    if (z0 != slabZ) {
      if (slabZ >= 0) flushSlab();
      slabZ = z0;
      if (progress) progress(double(r.k) / double(plan.dims[2]));
    }
    const size_t nOcc = keys->size();
    splitRow(tiling, r, [&](uint64_t key, uint32_t i0, uint32_t n) {
      std::vector<uint32_t>& v = slab[key];
      const uint32_t yz = ((r.j % kVoxModelSide) << 8) | ((r.k % kVoxModelSide) << 16);
      for (uint64_t cell = r.key + (i0 - r.i0), end = cell + n; cell < end; ++cell) {
        while (a < nOcc && (*keys)[a] < cell) ++a;
        const uint8_t index = a < nOcc && (*keys)[a] == cell && !cellIndex.empty() ? cellIndex[a] : solidIndex;
        v.push_back(uint32_t(cell - r.key + r.i0) % kVoxModelSide | yz | (uint32_t(index) << 24));
      }
    });
  });
  if (slabZ >= 0) flushSlab();
}

}  // namespace

std::vector<Rgb8> choosePalette(std::span<const Rgb8> colors, std::span<const uint64_t> weights) {
  VOX_CHECK(colors.size() == weights.size());
  std::vector<size_t> order(colors.size());
  std::iota(order.begin(), order.end(), 0);
  if (colors.size() <= 255) {
    std::vector<Rgb8> p(colors.begin(), colors.end());
    std::sort(p.begin(), p.end());
    return p;
  }
  struct Box {
    size_t begin, end;
    uint64_t weight;
  };
  auto boxWeight = [&](size_t b, size_t e) {
    uint64_t s = 0;
    for (size_t i = b; i < e; ++i) s += weights[order[i]];
    return s;
  };
  std::vector<Box> boxes{{0, order.size(), boxWeight(0, order.size())}};
  while (boxes.size() < 255) {
    // The heaviest box that still holds two colours.
    size_t pick = boxes.size();
    for (size_t b = 0; b < boxes.size(); ++b)
      if (boxes[b].end - boxes[b].begin > 1 && (pick == boxes.size() || boxes[b].weight > boxes[pick].weight)) pick = b;
    if (pick == boxes.size()) break;
    Box box = boxes[pick];
    std::array<int, 3> lo{255, 255, 255}, hi{0, 0, 0};
    for (size_t i = box.begin; i < box.end; ++i)
      for (int ch = 0; ch < 3; ++ch) {
        lo[ch] = std::min<int>(lo[ch], colors[order[i]][ch]);
        hi[ch] = std::max<int>(hi[ch], colors[order[i]][ch]);
      }
    int axis = 0;
    for (int ch = 1; ch < 3; ++ch)
      if (hi[ch] - lo[ch] > hi[axis] - lo[axis]) axis = ch;
    std::sort(order.begin() + long(box.begin), order.begin() + long(box.end), [&](size_t a, size_t b) {
      return colors[a][axis] != colors[b][axis] ? colors[a][axis] < colors[b][axis] : pack(colors[a]) < pack(colors[b]);
    });
    // Weighted median, keeping both halves non-empty.
    size_t split = box.begin + 1;
    uint64_t acc = weights[order[box.begin]];
    while (split < box.end - 1 && 2 * acc < box.weight) acc += weights[order[split++]];
    boxes[pick] = {box.begin, split, boxWeight(box.begin, split)};
    boxes.push_back({split, box.end, boxWeight(split, box.end)});
  }
  std::vector<Rgb8> palette;
  for (const Box& b : boxes) {
    std::array<double, 3> sum{0, 0, 0};
    for (size_t i = b.begin; i < b.end; ++i)
      for (int ch = 0; ch < 3; ++ch) sum[ch] += double(weights[order[i]]) * colors[order[i]][ch];
    Rgb8 c;
    for (int ch = 0; ch < 3; ++ch) c[ch] = uint8_t(std::clamp(sum[ch] / double(b.weight) + 0.5, 0.0, 255.0));
    palette.push_back(c);
  }
  return palette;
}

MagicaVoxelStats writeMagicaVoxel(std::ostream& out, const Grid& grid, std::span<const Rgb8> cellColors,
                                  Rgb8 solidColor, const std::function<void(double)>& progress) {
  const ColoredPieceSource whole = [&](const ColoredPieceVisitor& visit) { visit(grid, cellColors); };
  return writeMagicaVoxelPieces(out, grid, whole, solidColor, progress);
}

MagicaVoxelStats writeMagicaVoxelPieces(std::ostream& out, const Grid& plan, const ColoredPieceSource& pieces,
                                        Rgb8 solidColor, const std::function<void(double)>& progress) {
  const Tiling tiling{(plan.dims[0] + kVoxModelSide - 1) / kVoxModelSide,
                      (plan.dims[1] + kVoxModelSide - 1) / kVoxModelSide};
  const Census census = takeCensus(plan, tiling, pieces, solidColor);  // also checks the keys and runs
  const std::map<uint64_t, Tile>& tiles = census.tiles;
  MagicaVoxelStats stats;
  stats.models = uint32_t(tiles.size());
  stats.voxels = census.voxels;
  uint64_t children = 0, slabMax = 0;
  std::map<uint32_t, uint64_t> slabVoxels;
  for (const auto& [key, t] : tiles) {
    children += 24 + 16 + 4 * t.voxels;  // SIZE chunk, XYZI chunk
    slabVoxels[t.origin[2]] += t.voxels;
  }
  for (const auto& [z, n] : slabVoxels) slabMax = std::max(slabMax, n);
  const std::string graph = sceneGraph(tiles);
  children += graph.size() + 12 + 1024;  // scene graph, RGBA chunk
  if (children > uint64_t(INT32_MAX) - 20)
    fail<LimitError>("vox: ", stats.voxels, " voxels need ", children,
                     " bytes, more than the 2^31 - 1 that the "
                     "format's int32 chunk sizes allow (export a coarser grid or several bricks)");
  requireMemory(saturatingMul(slabMax, 4), "vox", "one 256-cell slab of voxels");

  const PaletteMap palette = buildPalette(census.weights);
  stats.gridColors = uint32_t(census.weights.size());
  stats.paletteColors = uint32_t(palette.palette.size());
  stats.paletteReduced = census.weights.size() > 255;
  const uint8_t solidIndex = census.solidOnly > 0 ? palette.index.at(pack(solidColor)) : 1;

  std::string buf = "VOX ";
  putU32(buf, 150);
  putChunkHeader(buf, "MAIN", 0, children);
  writeModels(out, buf, plan, tiling, tiles, pieces, palette, solidIndex, progress);
  buf += graph;
  putChunkHeader(buf, "RGBA", 1024, 0);
  for (size_t p = 0; p < 256; ++p) {
    const Rgb8 c = p < palette.palette.size() ? palette.palette[p] : Rgb8{0, 0, 0};
    for (int ch = 0; ch < 3; ++ch) buf.push_back(char(c[ch]));
    buf.push_back(char(p < palette.palette.size() ? 255 : 0));
  }
  out.write(buf.data(), std::streamsize(buf.size()));
  return stats;
}

}  // namespace vox
