// OpenVDB bridge (vdb_writer.h): the only file that includes OpenVDB. Built against Debian 12's libopenvdb-dev
// (OpenVDB 10.0.1); link openvdb, Imath and tbb (DEBIAN-NOTES.md).
// OpenVDB places voxel centres at integer index coordinates (a voxel spans index +-0.5), hence the half-cell in the
// translation.
#include "vox/export/vdb_writer.h"

#include <openvdb/io/Stream.h>
#include <openvdb/math/Maps.h>
#include <openvdb/math/Transform.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "export/export_budget.h"
#include "vox/core/checked_math.h"
#include "vox/core/error.h"
#include "vox/core/exact_number.h"
#include "vox/export/voxel_runs.h"
#include "vox/core/memory_budget.h"

namespace vox {

namespace {

// OpenVDB's map from index to world space: a cell's sides and its centre. Its constructor throws (an exception of
// OpenVDB's own, which no caller expects) when the product of the sides is zero or not finite, as for cells of 1e-120
// a side, which a grid may hold: refused here with the sides named.
openvdb::math::Transform::Ptr cellTransform(const Grid& grid) {
  openvdb::Vec3d scale, translate;
  for (int a = 0; a < 3; ++a) {
    const double side = (grid.bounds.hi[a] - grid.bounds.lo[a]) / double(grid.dims[a]);
    scale[a] = side;
    translate[a] = grid.bounds.lo[a] + 0.5 * side;
  }
  const double volume = scale[0] * scale[1] * scale[2];
  const bool representable = std::isfinite(volume) && volume != 0 && std::isfinite(1 / volume) &&
                             std::isfinite(translate[0] + translate[1] + translate[2]);
  try {
    if (representable)
      return std::make_shared<openvdb::math::Transform>(
          std::make_shared<openvdb::math::ScaleTranslateMap>(scale, translate));
  } catch (const openvdb::Exception&) {
  }
  fail<LimitError>("vdb: cells of ", exactNumber(scale[0]), " x ", exactNumber(scale[1]), " x ", exactNumber(scale[2]),
                   " are beyond OpenVDB's transform (the product of a cell's sides must be a nonzero finite number)");
}

// OpenVDB's index space is signed 32-bit.
void checkIndexRange(const Grid& grid) {
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] > uint32_t(INT32_MAX)) fail<LimitError>("vdb: ", grid.dims[a], " cells on an axis exceed 2^31");
}

// ---------------------------------------------------------------------------------------------------------------
// Memory of the trees, estimated before each fill. A fill of a box makes, on each level, a node for every block of
// that level the box meets without covering it (a block it covers becomes a tile of the level above), and a root
// entry for every 4096^3 block it meets: counted exactly per box from its corners, so a box of 2^63 cells costs six
// products, not a walk. Boxes that share a block are counted once each (an upper bound), and each level's count is
// capped by the grid's own number of blocks there.

using FloatTree = openvdb::FloatTree;
using Int2Node = FloatTree::RootNodeType::ChildNodeType;  // 4096^3 voxels
using Int1Node = Int2Node::ChildNodeType;                 // 128^3
using LeafNode = Int1Node::ChildNodeType;                 // 8^3

// Levels: leaves, lower internal nodes, upper internal nodes, root entries (one per upper node or root tile).
constexpr int kLevels = 4;
constexpr std::array<uint64_t, 3> kBlockSide{LeafNode::DIM, Int1Node::DIM, Int2Node::DIM};
// A leaf's values live in a heap array of its own. A root entry is a node of the root's std::map<Coord, NodeStruct>:
// key and value (a child pointer and a tile) plus the node's three pointers, colour and allocator header.
constexpr std::array<uint64_t, kLevels> kNodeBytes{sizeof(LeafNode) + LeafNode::SIZE * sizeof(float), sizeof(Int1Node),
                                                   sizeof(Int2Node), sizeof(openvdb::Coord) + 16 + 48};
// Root tiles (4096^3 cells each) beyond which a tree is refused whatever the memory: the root's table is a std::map
// that OpenVDB builds, writes and every reader loads one entry at a time (2^22 entries: about 300 MB and seconds
// each way); only a crafted grid reaches it (2^22 blocks of 4096^3 are 2^58 cells).
constexpr uint64_t kMaxRootEntries = uint64_t(1) << 22;

struct NodeTally {
  std::array<uint64_t, kLevels> n{};
  void add(const NodeTally& o) {
    for (int l = 0; l < kLevels; ++l) n[l] = saturatingAdd(n[l], o.n[l]);
  }
};

// The nodes a fill of the box [lo, hi] (inclusive cell indices) adds at most.
NodeTally boxNodes(const std::array<uint64_t, 3>& lo, const std::array<uint64_t, 3>& hi) {
  NodeTally t;
  for (int l = 0; l < 3; ++l) {
    const uint64_t side = kBlockSide[l];
    uint64_t met = 1, covered = 1;
    for (int a = 0; a < 3; ++a) {
      met = saturatingMul(met, hi[a] / side - lo[a] / side + 1);
      const uint64_t firstWhole = (lo[a] + side - 1) / side, endWhole = (hi[a] + 1) / side;
      covered = saturatingMul(covered, endWhole > firstWhole ? endWhole - firstWhole : 0);
    }
    t.n[l] = met - std::min(met, covered);
    if (l == 2) t.n[3] = met;
  }
  return t;
}

// The grid's own number of blocks on each level, which no tree of its voxels exceeds.
NodeTally gridBlocks(const Grid& grid) {
  NodeTally t;
  for (int l = 0; l < 3; ++l) {
    t.n[l] = 1;
    for (int a = 0; a < 3; ++a)
      t.n[l] = saturatingMul(t.n[l], (uint64_t(grid.dims[a]) + kBlockSide[l] - 1) / kBlockSide[l]);
  }
  t.n[3] = t.n[2];
  return t;
}

// The bytes of `t`'s nodes.
uint64_t nodeBytes(const NodeTally& t) {
  uint64_t bytes = 0;
  for (int l = 0; l < kLevels; ++l) bytes = saturatingAdd(bytes, saturatingMul(t.n[l], kNodeBytes[l]));
  return bytes;
}

// The density tree's estimate against the root-entry cap and, with `reservedBytes` for the count tree, the memory
// budget. Each tree's count on a level is capped by the grid's blocks there, the slab's by the two layers of blocks
// it can reach (a thin box ends in the slab being built and may begin in the one before).
class TreeBudget {
 public:
  TreeBudget(const Grid& grid, uint64_t reservedBytes) : caps_(gridBlocks(grid)), reservedBytes_(reservedBytes) {
    slabCaps_ = caps_;
    for (int l = 0; l < 3; ++l) {
      const uint64_t side = kBlockSide[l];
      const uint64_t plane = saturatingMul((grid.dims[0] + side - 1) / side, (grid.dims[1] + side - 1) / side);
      slabCaps_.n[l] = std::min(caps_.n[l], saturatingMul(2, plane));
    }
    slabCaps_.n[3] = slabCaps_.n[2];
  }

  // The bytes of the density tree's nodes `density` and the slab's `slab`, with the count tree's; root entries
  // over the cap throw LimitError.
  uint64_t bytes(const NodeTally& density, const NodeTally& slab) const {
    NodeTally d = density, s = slab;
    for (int l = 0; l < kLevels; ++l) {
      d.n[l] = std::min(d.n[l], caps_.n[l]);
      s.n[l] = std::min(s.n[l], slabCaps_.n[l]);
    }
    if (d.n[3] > kMaxRootEntries)
      fail<LimitError>("vdb: the voxels need ", describeCount(d.n[3]), " root tiles of 4096^3 cells, more than the ",
                       kMaxRootEntries, " a .vdb is written with (export a part of the grid)");
    return saturatingSum({nodeBytes(d), nodeBytes(s), reservedBytes_});
  }

 private:
  NodeTally caps_, slabCaps_;
  uint64_t reservedBytes_;
};

// The nodes of the count tree, exactly: one leaf, lower and upper node per distinct block holding an occupied cell.
// The blocks' ids nest (upper block, lower block within it, leaf within that), so one sort counts all three levels.
NodeTally countTreeNodes(const Grid& grid) {
  requireMemory(saturatingMul(grid.cellKeys.size(), sizeof(uint64_t)), "vdb", "the count grid's blocks");
  std::vector<uint64_t> ids(grid.cellKeys.size());
  for (size_t c = 0; c < ids.size(); ++c) {
    const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
    uint64_t id = 0;
    for (uint32_t v : {ijk[2] >> 12, ijk[1] >> 12, ijk[0] >> 12}) id = (id << 9) | v;  // dims <= 2^21
    for (uint32_t v : {ijk[2] >> 7, ijk[1] >> 7, ijk[0] >> 7}) id = (id << 5) | (v & 31);
    for (uint32_t v : {ijk[2] >> 3, ijk[1] >> 3, ijk[0] >> 3}) id = (id << 4) | (v & 15);
    ids[c] = id;
  }
  std::sort(ids.begin(), ids.end());
  NodeTally t;
  for (size_t c = 0; c < ids.size(); ++c) {
    t.n[0] += c == 0 || ids[c] != ids[c - 1];
    t.n[1] += c == 0 || ids[c] >> 12 != ids[c - 1] >> 12;
    t.n[2] += c == 0 || ids[c] >> 27 != ids[c - 1] >> 27;
  }
  t.n[3] = t.n[2];
  return t;
}

NodeTally treeNodes(const FloatTree& tree) {
  const std::vector<openvdb::Index32> counts = tree.nodeCount();  // leaves first; internal nodes only, no leaf walk
  NodeTally t;
  for (int l = 0; l < 3 && l < int(counts.size()); ++l) t.n[l] = counts[l];
  t.n[3] = tree.root().getTableSize();
  return t;
}

// Builds `density` from the voxel rows, merging rows into boxes: rows of one layer with the same x extent on
// consecutive y form rectangles, and equal rectangles on consecutive layers form boxes. Tree::sparseFill writes the
// nodes a box covers whole as tiles, so a filled interior costs its surface, not its volume (a closed cube at
// 1024^3, 10^9 solid cells, is one box). Boxes shallower than a leaf (8 layers) would still leave dense leaves; they
// go to a scratch tree per 8-layer slab that is pruned into tiles and merged before the next slab. Whole rows come
// as rectangles and whole planes as boxes (addPlanes), never row by row, so the work is bounded by the voxel
// intervals, not by the rows they cover. Every fill is checked against the TreeBudget first.
class DensityBuilder {
 public:
  DensityBuilder(const Grid& grid, uint64_t reservedBytes)
      : budget_(grid, reservedBytes),
        density_(openvdb::FloatGrid::create(0.0f)),
        slab_(openvdb::FloatGrid::create(0.0f)) {}

  // Cells i0 .. i0 + count - 1 of rows j0 .. j1 of layer k; rectangles of one layer come in increasing (j, i).
  void add(uint32_t i0, uint32_t count, uint32_t j0, uint32_t j1, uint32_t k) {
    if (int64_t(k) != layer_) {
      endLayer();
      if (int64_t(k & ~uint32_t(7)) != slabK_) {
        flushSlab();
        slabK_ = k & ~uint32_t(7);
      }
      layer_ = k;
    }
    const Span span{i0, count};
    auto it = rows_.find(span);
    if (it != rows_.end() && it->second.second + 1 == j0) {
      it->second.second = j1;
      return;
    }
    if (it != rows_.end()) rects_.push_back({span, it->second});
    rows_[span] = {j0, j1};
  }

  // Layers k0 .. k1 whole (nx by ny cells each), filled at once: they meet no rectangle of the layers being merged
  // (keys only ascend), and fills are unions.
  void addPlanes(uint32_t nx, uint32_t ny, uint32_t k0, uint32_t k1) { fill({{0, nx}, {0, ny - 1}}, k0, k1); }

  openvdb::FloatGrid::Ptr finish() {
    endLayer();
    for (const auto& [rect, k0] : boxes_) fill(rect, k0, uint32_t(layer_));
    boxes_.clear();
    flushSlab();
    density_->tree().prune();
    return density_;
  }

 private:
  using Span = std::pair<uint32_t, uint32_t>;                   // i0, count
  using Rect = std::pair<Span, std::pair<uint32_t, uint32_t>>;  // x span, y range [j0, j1]

  void endLayer() {
    if (layer_ < 0) return;
    for (const auto& [span, js] : rows_) rects_.push_back({span, js});
    rows_.clear();
    std::map<Rect, uint32_t> next;  // rectangle -> first layer of its box
    for (const Rect& rect : rects_) {
      auto it = boxes_.find(rect);
      const bool continues = it != boxes_.end() && boxLayer_ + 1 == layer_;
      next[rect] = continues ? it->second : uint32_t(layer_);
      if (it != boxes_.end() && continues) boxes_.erase(it);
    }
    for (const auto& [rect, k0] : boxes_) fill(rect, k0, uint32_t(boxLayer_));
    boxes_ = std::move(next);
    boxLayer_ = layer_;
    rects_.clear();
  }

  void fill(const Rect& rect, uint32_t k0, uint32_t k1) {
    const uint32_t i0 = rect.first.first, i1 = rect.first.first + rect.first.second - 1;
    const uint32_t j0 = rect.second.first, j1 = rect.second.second;
    const NodeTally more = boxNodes({i0, j0, k0}, {i1, j1, k1});
    const bool thick = k1 - k0 >= 7;
    require(thick, more);
    (thick ? densityNodes_ : slabNodes_).add(more);
    if (i0 == i1 && j0 == j1 && k0 == k1) {
      slab_->tree().setValueOn(openvdb::Coord(int(i0), int(j0), int(k0)), 1.0f);
      return;
    }
    auto& tree = thick ? density_->tree() : slab_->tree();
    tree.sparseFill(
        openvdb::CoordBBox(openvdb::Coord(int(i0), int(j0), int(k0)), openvdb::Coord(int(i1), int(j1), int(k1))), 1.0f,
        true);
  }

  // Throws LimitError unless the trees with `more` nodes in the density tree (thick) or the slab fit the budget.
  // The estimates add every fill's nodes, so boxes sharing a block count it once each (rows of one leaf up to 64
  // times); the first time they pass the budget, both trees are pruned and their nodes counted instead, and the
  // estimate goes on from there (again only while the trees hold less than half the budget, so that counting, a
  // walk over their internal nodes, is paid for by the fills that grew the estimate by that half).
  void require(bool thick, const NodeTally& more) {
    const auto bytes = [&] {
      NodeTally d = densityNodes_, s = slabNodes_;
      (thick ? d : s).add(more);
      return budget_.bytes(d, s);
    };
    if (bytes() <= limit_) return;
    if (recount_) {
      density_->tree().prune();
      slab_->tree().prune();
      densityNodes_ = treeNodes(density_->tree());
      slabNodes_ = treeNodes(slab_->tree());
      recount_ = budget_.bytes(densityNodes_, slabNodes_) < limit_ / 2;
    }
    requireMemory(bytes(), "vdb", "the OpenVDB trees of the voxels", "need at least");
  }

  void flushSlab() {
    slab_->tree().prune();
    // What the slab really holds once pruned replaces its estimate; merging may share nodes with density_ (counted
    // twice, an upper bound).
    densityNodes_.add(treeNodes(slab_->tree()));
    slabNodes_ = {};
    density_->tree().merge(slab_->tree());
    slab_->clear();
  }

  TreeBudget budget_;
  NodeTally densityNodes_, slabNodes_;    // upper bounds of what each tree holds
  bool recount_ = true;                   // whether the estimate may still be replaced by a count
  uint64_t limit_ = memoryBudgetBytes();  // read once: it asks the system for its memory
  openvdb::FloatGrid::Ptr density_, slab_;
  int64_t layer_ = -1, boxLayer_ = -2, slabK_ = -1;
  std::map<Span, std::pair<uint32_t, uint32_t>> rows_;  // open rectangles of this layer, by x span
  std::vector<Rect> rects_;                             // closed rectangles of this layer
  std::map<Rect, uint32_t> boxes_;                      // boxes open up to boxLayer_
};

// The interval of keys [first, end) as pieces in key order: a part of a row, whole rows of one layer (a rectangle),
// whole layers (a box), whole rows of one layer, a part of a row; at most five pieces whatever its length.
void addInterval(DensityBuilder& builder, const std::array<uint32_t, 3>& dims, uint64_t first, uint64_t end) {
  const uint64_t nx = dims[0], ny = dims[1];
  auto row = [&](uint64_t key, uint64_t count) {
    const uint64_t r = key / nx;
    builder.add(uint32_t(key % nx), uint32_t(count), uint32_t(r % ny), uint32_t(r % ny), uint32_t(r / ny));
  };
  // Whole rows r0 .. r1 - 1 (row index r = j + ny * k).
  auto rows = [&](uint64_t r0, uint64_t r1) {
    if (r0 % ny != 0) {
      const uint64_t stop = std::min(r1, (r0 / ny + 1) * ny);
      builder.add(0, uint32_t(nx), uint32_t(r0 % ny), uint32_t((stop - 1) % ny), uint32_t(r0 / ny));
      r0 = stop;
    }
    if (r1 - r0 >= ny) {
      const uint64_t planes = (r1 - r0) / ny;
      builder.addPlanes(uint32_t(nx), uint32_t(ny), uint32_t(r0 / ny), uint32_t(r0 / ny + planes - 1));
      r0 += planes * ny;
    }
    if (r0 < r1) builder.add(0, uint32_t(nx), 0, uint32_t((r1 - 1) % ny), uint32_t(r0 / ny));
  };
  if (first / nx == (end - 1) / nx) return row(first, end - first);
  if (first % nx != 0) {
    const uint64_t stop = (first / nx + 1) * nx;
    row(first, stop - first);
    first = stop;
  }
  const uint64_t wholeEnd = end / nx * nx;
  if (first < wholeEnd) rows(first / nx, wholeEnd / nx);
  if (wholeEnd < end && wholeEnd >= first) row(wholeEnd, end - wholeEnd);
}

openvdb::FloatGrid::Ptr buildDensity(const Grid& grid, uint64_t reservedBytes,
                                     const std::function<void(double)>& progress) {
  DensityBuilder builder(grid, reservedBytes);
  const double cells = double(grid.cellCount());
  forEachVoxelInterval(grid, [&](uint64_t first, uint64_t end) {
    if (progress) progress(double(first) / cells);
    addInterval(builder, grid.dims, first, end);
  });
  return builder.finish();
}

// A float grid, not Int32Grid: pyopenvdb (Debian's python3-openvdb) refuses to read files holding int32 grids, and
// counts below 2^24 are exact in float.
openvdb::FloatGrid::Ptr buildCount(const Grid& grid) {
  auto count = openvdb::FloatGrid::create(0.0f);
  auto acc = count->getAccessor();
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) {
    const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
    acc.setValueOn(openvdb::Coord(int(ijk[0]), int(ijk[1]), int(ijk[2])),
                   float(grid.cellStart[c + 1] - grid.cellStart[c]));
  }
  return count;
}

// The --sdf band as an OpenVDB level set: `surface`, class level set, background HALF x voxel size, the band's
// cells active with their distance (rounded to float, within the background), the rest inactive and signed by
// OpenVDB's own flood fill. A level set needs cubic voxels: other cells are refused.
openvdb::FloatGrid::Ptr buildLevelSet(const Grid& grid, const openvdb::math::Transform::Ptr& transform) {
  double lo = INFINITY, hi = 0;
  double size[3];
  for (int a = 0; a < 3; ++a) {
    size[a] = (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a];
    lo = std::min(lo, size[a]), hi = std::max(hi, size[a]);
  }
  if (hi > lo * (1 + 1e-9))
    fail<UsageError>("a level set needs cubic cells; this grid's are ", size[0], " x ", size[1], " x ", size[2],
                     " (voxelize with --res, which keeps cells cubic, or export .npz)");
  const float background = float(grid.sdfHalfWidth * lo);
  auto surface = openvdb::FloatGrid::create(background);
  auto acc = surface->getAccessor();
  for (size_t b = 0; b < grid.sdfKeys.size(); ++b) {
    const auto ijk = cellIndex(grid.dims, grid.sdfKeys[b]);
    const float d = std::clamp(float(grid.sdfValues[b]), -background, background);
    acc.setValueOn(openvdb::Coord(int(ijk[0]), int(ijk[1]), int(ijk[2])), d);
  }
  openvdb::tools::signedFloodFill(surface->tree());
  surface->setName("surface");
  surface->setGridClass(openvdb::GRID_LEVEL_SET);
  surface->setTransform(transform->copy());
  return surface;
}

}  // namespace

VdbStats writeVdb(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress) {
  checkIndexRange(grid);
  if (grid.cellStart.size() != grid.cellKeys.size() + 1 || grid.cellStart.back() > grid.primIds.size())
    fail<InputError>("grid: inconsistent cell table (", grid.cellKeys.size(), " cells, ", grid.cellStart.size(),
                     " offsets)");
  openvdb::initialize();  // registers the grid types; idempotent and thread-safe
  const auto transform = cellTransform(grid);
  tallyVoxels(grid);  // the keys and runs checked (InputError) before they are counted into blocks
  // The count tree is built after the density tree, which keeps room for it in the budget.
  const uint64_t countBytes = nodeBytes(countTreeNodes(grid));
  auto density = buildDensity(grid, countBytes, progress);  // also checks the keys and solid runs
  density->setName("density");
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  density->setTransform(transform);
  auto count = buildCount(grid);
  count->setName("count");
  count->setTransform(transform->copy());

  if (!grid.fractions.empty()) {  // the density holds how much of each occupied cell is inside (solid cells: 1)
    auto acc = density->getAccessor();
    for (size_t c = 0; c < grid.cellKeys.size(); ++c) {
      const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
      acc.setValueOn(openvdb::Coord(int(ijk[0]), int(ijk[1]), int(ijk[2])), float(grid.fractions[c]));
    }
  }
  openvdb::GridPtrVec grids{density, count};
  if (grid.sdfHalfWidth > 0) grids.push_back(buildLevelSet(grid, transform));
  openvdb::io::Stream(out).write(grids);
  return {density->activeVoxelCount(), density->tree().leafCount()};
}

}  // namespace vox
