// numpy .npz output of a grid (DESIGN.md "Distance and volume"): the dense arrays learning data loaders read, in
// numpy's own format (a zip of .npy files, stored uncompressed), loadable by numpy.load without libvox.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>

#include "vox/core/grid.h"

namespace vox {

// Largest .npz written: the zip format without its ZIP64 extension (4 GiB); larger grids go to .vdb, which is sparse.
inline constexpr uint64_t kMaxNpzBytes = (uint64_t(1) << 32) - (uint64_t(1) << 20);

// Writes arrays of shape (nx, ny, nz), index [i, j, k] the cell (i, j, k) (stored in Fortran order, x fastest, as
// the cell keys run):
//  - `occupancy` (uint8): 1 in occupied cells; `solid` (uint8): 1 in solid cells (--fill);
//  - `sdf` (float64), with distances: the signed distance at band cells' centres, NaN elsewhere;
//  - `fraction` (float64), with fractions: each occupied cell's fraction, 1 in solid cells, 0 elsewhere;
//  - `bounds` (2, 3) float64 (lo, hi), `dims` (3,) int64, `transform` (4, 4) float64: the map from index (i, j, k, 1)
//    to the world position of the cell's centre.
// Throws LimitError before allocating when the file would exceed kMaxNpzBytes or the memory budget.
// Returns the bytes written.
uint64_t writeNpz(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress = {});

}  // namespace vox
