// OpenVDB bridge (vdb_writer.h): the only file that includes OpenVDB. Built against Debian 12's libopenvdb-dev
// (OpenVDB 10.0.1); link openvdb, Imath and tbb (DEBIAN-NOTES.md).
// OpenVDB places voxel centres at integer index coordinates (a voxel spans index +-0.5), hence the half-cell in the
// translation.
#include "vox/export/vdb_writer.h"

#include <openvdb/io/Stream.h>
#include <openvdb/math/Maps.h>
#include <openvdb/math/Transform.h>
#include <openvdb/openvdb.h>

#include <map>
#include <vector>

#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"

namespace vox {

namespace {

openvdb::math::Transform::Ptr cellTransform(const Grid& grid) {
  openvdb::Vec3d scale, translate;
  for (int a = 0; a < 3; ++a) {
    const double side = (grid.bounds.hi[a] - grid.bounds.lo[a]) / double(grid.dims[a]);
    scale[a] = side;
    translate[a] = grid.bounds.lo[a] + 0.5 * side;
  }
  return std::make_shared<openvdb::math::Transform>(
      std::make_shared<openvdb::math::ScaleTranslateMap>(scale, translate));
}

// OpenVDB's index space is signed 32-bit.
void checkIndexRange(const Grid& grid) {
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] > uint32_t(INT32_MAX)) fail<LimitError>("vdb: ", grid.dims[a], " cells on an axis exceed 2^31");
}

// Builds `density` from the voxel rows, merging rows into boxes: rows of one layer with the same x extent on
// consecutive y form rectangles, and equal rectangles on consecutive layers form boxes. Tree::sparseFill writes the
// nodes a box covers whole as tiles, so a filled interior costs its surface, not its volume (a closed cube at
// 1024^3, 10^9 solid cells, is one box). Boxes shallower than a leaf (8 layers) would still leave dense leaves; they
// go to a scratch tree per 8-layer slab that is pruned into tiles and merged before the next slab.
class DensityBuilder {
 public:
  DensityBuilder() : density_(openvdb::FloatGrid::create(0.0f)), slab_(openvdb::FloatGrid::create(0.0f)) {}

  void add(const VoxelRow& r) {
    if (int64_t(r.k) != layer_) {
      endLayer();
      if (int64_t(r.k & ~uint32_t(7)) != slabK_) {
        flushSlab();
        slabK_ = r.k & ~uint32_t(7);
      }
      layer_ = r.k;
    }
    const Span span{r.i0, r.count};
    auto it = rows_.find(span);
    if (it != rows_.end() && it->second.second + 1 == r.j) {
      it->second.second = r.j;
      return;
    }
    if (it != rows_.end()) rects_.push_back({span, it->second});
    rows_[span] = {r.j, r.j};
  }

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
    const int i0 = int(rect.first.first), i1 = int(rect.first.first + rect.first.second - 1);
    const int j0 = int(rect.second.first), j1 = int(rect.second.second);
    if (i0 == i1 && j0 == j1 && k0 == k1) {
      slab_->tree().setValueOn(openvdb::Coord(i0, j0, int(k0)), 1.0f);
      return;
    }
    auto& tree = k1 - k0 >= 7 ? density_->tree() : slab_->tree();
    tree.sparseFill(openvdb::CoordBBox(openvdb::Coord(i0, j0, int(k0)), openvdb::Coord(i1, j1, int(k1))), 1.0f, true);
  }

  void flushSlab() {
    slab_->tree().prune();
    density_->tree().merge(slab_->tree());
    slab_->clear();
  }

  openvdb::FloatGrid::Ptr density_, slab_;
  int64_t layer_ = -1, boxLayer_ = -2, slabK_ = -1;
  std::map<Span, std::pair<uint32_t, uint32_t>> rows_;  // open rectangles of this layer, by x span
  std::vector<Rect> rects_;                             // closed rectangles of this layer
  std::map<Rect, uint32_t> boxes_;                      // boxes open up to boxLayer_
};

openvdb::FloatGrid::Ptr buildDensity(const Grid& grid, const std::function<void(double)>& progress) {
  DensityBuilder builder;
  const double nz = double(grid.dims[2]);
  uint32_t lastK = UINT32_MAX;
  forEachVoxelRow(grid, [&](const VoxelRow& r) {
    if (progress && r.k != lastK) progress(double(r.k) / nz);
    lastK = r.k;
    builder.add(r);
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

}  // namespace

VdbStats writeVdb(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress) {
  checkIndexRange(grid);
  if (grid.cellStart.size() != grid.cellKeys.size() + 1 || grid.cellStart.back() > grid.primIds.size())
    fail<InputError>("grid: inconsistent cell table (", grid.cellKeys.size(), " cells, ", grid.cellStart.size(),
                     " offsets)");
  openvdb::initialize();  // registers the grid types; idempotent and thread-safe
  const auto transform = cellTransform(grid);
  auto density = buildDensity(grid, progress);  // also checks the keys and solid runs
  density->setName("density");
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  density->setTransform(transform);
  auto count = buildCount(grid);
  count->setName("count");
  count->setTransform(transform->copy());

  openvdb::GridPtrVec grids{density, count};
  openvdb::io::Stream(out).write(grids);
  return {density->activeVoxelCount(), density->tree().leafCount()};
}

}  // namespace vox
