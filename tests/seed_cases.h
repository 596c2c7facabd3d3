// The course's assignment 5 and 6 scenes with the grid sizes of their command lines (seed-scenes/6837/README.md;
// scenes without one: 10 10 10), shared by the voxelizer's and the renderer's seed-scene tests.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>

namespace vox::testing {

struct SeedCase {
  const char* file;  // in seed-scenes/6837/scenes/
  std::array<uint32_t, 3> dims;
};

inline constexpr SeedCase kSeedCases[] = {
    {"scene5_01_sphere.txt", {1, 1, 1}},
    {"scene5_01_sphere.txt", {5, 5, 5}},
    {"scene5_01_sphere.txt", {15, 15, 15}},
    {"scene5_02_spheres.txt", {15, 15, 15}},
    {"scene5_02_spheres.txt", {15, 15, 3}},
    {"scene5_02_spheres.txt", {8, 8, 8}},
    {"scene5_03_offcenter_spheres.txt", {20, 20, 20}},
    {"scene5_04_plane_test.txt", {15, 15, 15}},
    {"scene5_05_sphere_triangles.txt", {20, 20, 10}},
    {"scene5_06_bunny_mesh_200.txt", {10, 10, 7}},
    {"scene5_07_bunny_mesh_1k.txt", {15, 15, 12}},
    {"scene5_08_bunny_mesh_5k.txt", {20, 20, 15}},
    {"scene5_09_bunny_mesh_40k.txt", {40, 40, 33}},
    {"scene5_10_scale_translate.txt", {15, 15, 15}},
    {"scene5_11_rotated_triangles.txt", {15, 15, 9}},
    {"scene5_12_nested_transformations.txt", {30, 30, 30}},
    {"scene6_01_sphere.txt", {10, 10, 10}},
    {"scene6_02_sphere_triangles.txt", {10, 10, 10}},
    {"scene6_03_sphere_plane.txt", {10, 10, 10}},
    {"scene6_04_bunny_mesh_200.txt", {10, 10, 7}},
    {"scene6_05_bunny_mesh_1k.txt", {15, 15, 12}},
    {"scene6_06_bunny_mesh_5k.txt", {20, 20, 15}},
    {"scene6_07_bunny_mesh_40k.txt", {40, 40, 33}},
    {"scene6_08_scale_translate.txt", {15, 15, 15}},
    {"scene6_09_rotated_triangles.txt", {15, 15, 9}},
    {"scene6_10_nested_transformations.txt", {30, 30, 30}},
    {"scene6_11_mirrored_floor.txt", {40, 10, 40}},
    {"scene6_12_faceted_gem.txt", {20, 20, 20}},
    {"scene6_13_checkerboard.txt", {10, 10, 10}},
    {"scene6_14_glass_sphere.txt", {20, 20, 20}},
    {"scene6_15_marble_cubes.txt", {10, 10, 10}},
    {"scene6_16_wood_cubes.txt", {10, 10, 10}},
    {"scene6_17_marble_vase.txt", {15, 30, 15}},
    {"scene6_18_6.837_logo.txt", {80, 30, 3}},
};

// GoogleTest names a parameter by this (found by argument-dependent lookup, hence here).
inline void PrintTo(const SeedCase& c, std::ostream* os) {
  *os << c.file << " --grid " << c.dims[0] << " " << c.dims[1] << " " << c.dims[2];
}

}  // namespace vox::testing
