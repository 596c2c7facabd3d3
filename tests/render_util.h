// Helpers shared by the rendering tests: a grid of given dimensions, an image through a given accelerator, and the
// count of pixels that differ bit for bit.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "vox/trace/accel.h"
#include "vox/trace/render.h"
#include "vox/voxelize/voxelize.h"

namespace vox::testing {

inline Grid voxelizeWith(const Scene& scene, std::array<uint32_t, 3> dims,
                         OverlapMethod method = OverlapMethod::Exact) {
  VoxelizeOptions o;
  o.dims = dims;
  o.method = method;
  return voxelizeScene(scene, o);
}

inline Image renderWith(const Scene& scene, const Grid& grid, AccelKind kind, const RenderOptions& ro,
                        RenderStats* stats = nullptr) {
  const Accel accel = buildAccel(scene, grid, kind);
  return traceImage(scene, accel, ro, stats);
}

// Number of pixels whose values differ at all (bitwise on the float values).
inline int differingPixels(const Image& a, const Image& b) {
  EXPECT_EQ(a.pixels.size(), b.pixels.size());
  int count = 0;
  for (size_t p = 0; p + a.channels <= a.pixels.size() && p + a.channels <= b.pixels.size(); p += a.channels)
    count += std::memcmp(&a.pixels[p], &b.pixels[p], a.channels * sizeof(float)) != 0;
  return count;
}

}  // namespace vox::testing
