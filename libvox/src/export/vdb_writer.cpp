// OpenVDB bridge (vdb_writer.h): the only file that includes OpenVDB. Built against Debian 12's libopenvdb-dev
// (OpenVDB 10.0.1); link openvdb, Imath and tbb (DEBIAN-NOTES.md).
// OpenVDB places voxel centres at integer index coordinates (a voxel spans index +-0.5), hence the half-cell in the
// translation. Tree::sparseFill fills whole child nodes as tiles but leaves partial leaves dense, so long runs are
// filled into a scratch tree per 8-layer slab, pruned into tiles, and merged into the result (Tree::merge steals
// the nodes; the slabs never overlap).
#include "vox/export/vdb_writer.h"

#include <openvdb/io/Stream.h>
#include <openvdb/math/Maps.h>
#include <openvdb/math/Transform.h>
#include <openvdb/openvdb.h>

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

openvdb::FloatGrid::Ptr buildDensity(const Grid& grid, const std::function<void(double)>& progress) {
  auto density = openvdb::FloatGrid::create(0.0f);
  auto slab = openvdb::FloatGrid::create(0.0f);
  auto acc = slab->getAccessor();
  int64_t slabK = -1;  // first z layer of the slab being built
  auto closeSlab = [&] {
    slab->tree().prune();
    density->tree().merge(slab->tree());
    slab->clear();
  };
  const double nz = double(grid.dims[2]);
  forEachVoxelRow(grid, [&](const VoxelRow& r) {
    const int64_t k8 = r.k & ~uint32_t(7);
    if (k8 != slabK) {
      if (slabK >= 0) closeSlab();
      slabK = k8;
      if (progress) progress(double(r.k) / nz);
    }
    const int i = int(r.i0), j = int(r.j), k = int(r.k);
    if (r.count >= 16) {
      slab->tree().sparseFill(openvdb::CoordBBox(openvdb::Coord(i, j, k), openvdb::Coord(i + int(r.count) - 1, j, k)),
                              1.0f, true);
    } else {
      for (uint32_t c = 0; c < r.count; ++c) acc.setValueOn(openvdb::Coord(i + int(c), j, k), 1.0f);
    }
  });
  if (slabK >= 0) closeSlab();
  density->tree().prune();
  return density;
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
