#include "options.h"

#include "../common/cli_app.h"

namespace vox::export_tool {

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("grid", opt.grid, "Input grid file (.vgrid)")->required();
  app.add_option(
         "-o,--output", opt.output,
         "Output mesh: .ply (binary unless --ascii, face colours), .obj (vertex colours), .off (face "
         "colours), .stl (binary unless --ascii, no colours), .glb/.gltf (vertex colours); voxels: .binvox "
         "(binvox, cubic voxels), .vox (MagicaVoxel, palette from --color), .vdb (OpenVDB grids density (or the "
         "volume fractions) and count, and a level set `surface` of the --sdf distances), .npz (numpy: dense "
         "occupancy, solid, sdf, fraction, bounds, dims, transform); .html: an interactive viewer page (three.js "
         "inside, opens from disk, no network)")
      ->required();
  app.add_option("--faces", opt.faces,
                 "all: a closed cube of 12 triangles per voxel; exposed (default): the quads between voxels and "
                 "empty cells, vertices shared, closed and 2-manifold; merged: the exposed quads merged into "
                 "rectangles of one colour, still closed, 2-manifold and free of T-junctions (STL and glTF get "
                 "triangles)")
      ->check(CLI::IsMember({"all", "exposed", "merged"}));
  app.add_option("--color", opt.color,
                 "count (default): primitives per cell on the viridis ramp of vox-trace --mode voxels (log scale, 1 "
                 "to the grid's maximum); material: the diffuse colour of the material held by the majority of the "
                 "cell's primitives (ties: lowest material index); none. Solid cells are grey.")
      ->check(CLI::IsMember({"count", "material", "none"}));
  app.add_flag("--ascii", opt.ascii, "Write ASCII PLY or STL instead of binary");
  app.add_flag("--stats", opt.stats,
               "Print statistics (name: value) on stderr: voxels, vertices, faces, exposed and merged face counts "
               "and their ratio, times");
  cli::addCommonOptions(app, opt.common);
  app.footer("Exit codes: 0 ok, 1 usage (including an unknown output extension), 2 bad input, 3 cannot write.");
}

std::optional<int> parseCommandLine(int argc, char** argv, Options& opt) {
  CLI::App app{
      "Write the voxels of a grid file (occupied and solid cells) as a mesh for MeshLab, Blender and "
      "other mesh tools; the format follows the output's extension.",
      "vox-export"};
  addOptions(app, opt);
  return cli::parse(app, argc, argv);
}

}  // namespace vox::export_tool
