// binvox (Patrick Min's voxel format, read by binvox-rw-py, trimesh and ShapeNet pipelines): an ASCII header
//   #binvox 1 / dim D D D / translate tx ty tz / scale s / data
// then (value, count) byte pairs run-length encoding a dense cube of D^3 bits in x-z-y order (index
// x*D*D + z*D + y: x slowest, y fastest; count 1..255). A voxel (x, y, z) covers the world box
// translate + scale * [x, x+1] / D (and likewise on y, z): binvox voxels are cubes.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <ostream>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/export/voxel_runs.h"

namespace vox {

// How a grid maps onto the binvox cube.
struct BinvoxLayout {
  uint32_t dim = 1;      // D = max(nx, ny, nz): the grid sits in the corner x < nx, y < ny, z < nz, the rest empty
  Vec3 translate;        // world position of the cube's corner: the grid's bounds.lo
  double scale = 1;      // world side of the whole cube: D times the voxel side
  double voxelSide = 1;  // the cell side of the grid's axis with the most cells (ties: x, then y), the one --res sets
  // How far the grid's cells are from cubes: max over axes of n_a * |cell_a - voxelSide| / voxelSide, the shift of
  // the grid's far face, in voxels, when its cells are written as cubes of voxelSide. 0 for cubic cells.
  double farFaceShiftVoxels = 0;
};

// Largest cube side written: binvox readers expand the cube densely (binvox-rw-py holds D^3 booleans).
inline constexpr uint32_t kBinvoxMaxDim = 4096;

// The layout of `grid` in binvox. Throws LimitError when max(nx, ny, nz) exceeds kBinvoxMaxDim.
BinvoxLayout binvoxLayout(const Grid& grid);

// Writes the voxels of `grid` (occupied and solid cells) as binvox to `out`. Streams: memory is the runs' start and
// end events plus one plane of D*D bits, never the D^3 cube (checked against the memory budget: LimitError). Cells
// that are not cubes are written as cubes of layout.voxelSide (binvox has one scale); the caller warns when
// layout.farFaceShiftVoxels matters. progress(fraction) is called now and then when given.
// Throws LimitError as binvoxLayout, InputError for an inconsistent grid; write errors are the stream's.
BinvoxLayout writeBinvox(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress = {});
// The same from the plan of a grid (bounds and dims; its cells are not read) and a source of its rows, asked twice
// (to count the events per plane, then to place them; it must give the same rows both times). vox-export writes a
// grid set this way, one layer of bricks in memory at a time instead of the whole grid.
BinvoxLayout writeBinvox(std::ostream& out, const Grid& plan, const VoxelRowSource& rows,
                         const std::function<void(double)>& progress = {});

}  // namespace vox
