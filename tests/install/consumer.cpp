// A program of a libvox user, built against an installed tree (tests/cli/install_tree.sh): voxelizes one triangle,
// writes a grid file, reads it back and checks that the cells survived. Exit 0 and one line on success.
#include <cstdio>
#include <exception>

#include "vox/io/grid_file.h"
#include "vox/voxelize/voxelize.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUT.vgrid\n");
    return 2;
  }
  try {
    vox::Scene scene;
    scene.materials.push_back(vox::Material{});
    scene.triangles.push_back(vox::Triangle{{vox::Vec3{0, 0, 0}, vox::Vec3{1, 0, 0}, vox::Vec3{0, 1, 0.5}}, 0});
    vox::VoxelizeOptions options;
    options.dims = std::array<uint32_t, 3>{4, 4, 4};
    const vox::Grid grid = vox::voxelizeScene(scene, options);
    vox::writeGridFile(argv[1], scene, grid);
    const vox::GridFile back = vox::readGridFile(argv[1]);
    if (grid.occupiedCount() == 0 || back.grid.cellKeys.size() != grid.cellKeys.size() ||
        back.grid.primIds.size() != grid.primIds.size() || back.scene.triangles.size() != 1) {
      std::fprintf(stderr, "consumer: the grid read back differs from the one written\n");
      return 1;
    }
    for (size_t i = 0; i < grid.cellKeys.size(); ++i)
      if (back.grid.cellKeys[i] != grid.cellKeys[i]) return 1;
    std::printf("consumer: %zu occupied cells of %llu written and read back\n", grid.occupiedCount(),
                static_cast<unsigned long long>(grid.cellCount()));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
