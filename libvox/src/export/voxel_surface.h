// The parts of the voxel meshes (vox/export/voxel_mesh.h) that their three files share: packed colours, the voxels
// and their lattice (voxel_mesh.cpp), the exposed surface (exposed_surface.cpp) and its merged rectangles
// (merged_mesh.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/export/voxel_mesh.h"

namespace vox::voxel_surface {

inline constexpr uint32_t kNoColor = 0;
// Colours are packed as 0x01BBGGRR: the top byte marks "has a colour", so that every colour differs from kNoColor.
inline uint32_t packColor(const Rgb8& c) { return 0x01000000u | c[0] | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16); }
inline Rgb8 unpackColor(uint32_t c) { return {uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)}; }

struct Voxels {
  std::vector<uint64_t> keys;    // sorted, unique
  std::vector<uint32_t> colors;  // packed, kNoColor without colour
};

// The lattice coordinate of cell boundary i on each axis, in world space.
struct Lattice {
  Box bounds;
  std::array<uint32_t, 3> dims;
  Vec3 point(uint64_t i, uint64_t j, uint64_t k) const {
    return {cellBoundary(bounds, dims, 0, int64_t(i)), cellBoundary(bounds, dims, 1, int64_t(j)),
            cellBoundary(bounds, dims, 2, int64_t(k))};
  }
};

inline void checkVertexCount(uint64_t n) {
  if (n >= (uint64_t(1) << 32))
    fail<LimitError>("voxel mesh: ", n, " vertices exceed the 2^32 limit of the mesh formats");
}

// One exposed unit square: the plane x_axis = plane, facing + (positive) or -, with its minimum corner at in-plane
// coordinates (u, v) along axes (axis+1)%3 and (axis+2)%3, and its vertices at corners (0,0) (1,0) (1,1) (0,1).
struct Square {
  std::array<uint32_t, 4> vid;
  uint32_t color;
  uint32_t u, v, plane;
  uint8_t axis, positive;
};

struct ExposedSurface {
  std::vector<Vec3> positions;
  std::vector<uint8_t> split;  // per vertex: its lattice point has several vertices (several sheets of surface)
  std::vector<Square> squares;
};

// The exposed unit squares of the voxels and their vertices (FaceMode::Exposed before it becomes quads): see
// exposed_surface.cpp for how lattice points are split into vertices. Throws LimitError for a grid too large.
ExposedSurface buildExposed(const Voxels& vox, const Lattice& lat);
// One quad per exposed square.
VoxelMesh exposedMesh(ExposedSurface&& surface, bool colored);
// FaceMode::Merged: the squares of each plane merged greedily into rectangles of one colour.
VoxelMesh mergedMesh(ExposedSurface&& surface, const std::array<uint32_t, 3>& dims, bool colored);

// Triangles (appended to `tris`) of the rectangle `poly` (vertex ids into `pos`) whose sides carry extra vertices;
// corner[k] is the position in poly of its k-th corner. No zero-area triangle.
void triangulateRectangle(const std::vector<uint32_t>& poly, const std::vector<Vec3>& pos,
                          const std::array<size_t, 4>& corner, std::vector<uint32_t>& tris);

}  // namespace vox::voxel_surface
