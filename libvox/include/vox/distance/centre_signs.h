// Inside or outside, for many cell centres at once: the signs of --sdf and libvox.sdf (DESIGN.md "Distance and
// volume"), InsideTest's decision at every centre, a row at a time.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/distance/sdf.h"

namespace vox {

// For each cell of `keys` (sorted): whether its centre is inside by `test` (InsideTest::inside, equal bit for bit),
// each row's crossings found once. Throws vox::Error "... cancelled" when `progress` (as
// DistanceQueryOptions::progress) returns false.
std::vector<uint8_t> centresInside(const Grid& grid, const InsideTest& test, std::span<const uint64_t> keys,
                                   const std::function<bool(double)>& progress = {});

// centresInside for the occupied cells (cellKeys order), with the scene's own InsideTest.
std::vector<uint8_t> occupiedCentresInside(const Grid& grid, const Scene& scene,
                                           const std::function<bool(double)>& progress = {});

}  // namespace vox
