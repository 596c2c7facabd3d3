// Distances beyond the --sdf band (DESIGN.md "Distance and volume"): the signed distance at every cell centre of a
// grid (libvox.sdf), and the nearest primitive of any points (Grid.distance). Both use NearestPrimitive, so their
// values equal the band's bit for bit where both exist.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/distance/nearest.h"
#include "vox/distance/sdf.h"

namespace vox {

struct DistanceQueryOptions {
  // Called with a fraction in [0, 1], possibly from worker threads, at least every 0.05 s of work; return false to
  // cancel (throws vox::Error "... cancelled").
  std::function<bool(double)> progress;
};

// The signed distance (world units, negative inside) at the centre of every cell, written to
// out[i * strides[0] + j * strides[1] + k * strides[2]]: the Euclidean distance to the nearest bounded primitive,
// signed as the band signs it (InsideTest at every centre; grid.solidRuns are not used). Precondition: `out` spans
// every index. A scene without bounded primitives
// gives +infinity. Work spread over the caller's TBB arena; the result does not depend on the thread count.
void denseSignedDistances(const Grid& grid, const Scene& scene, std::span<double> out,
                          const std::array<uint64_t, 3>& strides, const DistanceQueryOptions& options = {});

// For each point (x, y, z triples of `points`): the distance to the nearest bounded primitive (negative inside,
// by InsideTest, when `signedDistance`), that primitive's id (the grid's ids: triangles, then spheres; -1 and
// +infinity when the scene has none), and its nearest point (NaN without one). Each output holds one entry (three
// for `closest`) per point. Throws InputError naming points[i] for a coordinate that is not finite.
struct PointDistanceOutput {
  std::span<double> distance;
  std::span<int64_t> primitive;
  std::span<double> closest;
};
void pointDistances(const Scene& scene, std::span<const double> points, bool signedDistance,
                    const PointDistanceOutput& out, const DistanceQueryOptions& options = {});
// The same with the search structure and the inside test built by the caller (and kept across calls): `inside`
// null for unsigned distances.
void pointDistances(const NearestPrimitive& nearest, const InsideTest* inside, std::span<const double> points,
                    const PointDistanceOutput& out, const DistanceQueryOptions& options = {});

}  // namespace vox
