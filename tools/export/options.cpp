#include "options.h"

#include <algorithm>
#include <string>
#include <vector>

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
  app.add_option_function<std::vector<std::string>>(
         "--surface",
         [&opt](const std::vector<std::string>& level) {
           if (level.empty() || level[0].empty()) return void(opt.surface = 0.0);
           double value = 0;
           if (!CLI::detail::lexical_cast(level[0], value))
             throw CLI::ValidationError("--surface", "LEVEL " + level[0] + " is not a number");
           opt.surface = value;
         },
         "Write the level set d = LEVEL (default 0, world units) of the grid's signed distances (vox-voxelize "
         "--sdf) instead of the voxels: closed, two-manifold, oriented outward, by marching tetrahedra over the "
         "cell centres; LEVEL > 0 grows the solid, < 0 shrinks it, within the band less a cell's diagonal")
      ->expected(0, 1)
      ->type_name("[LEVEL]");
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
  // "--surface GRID -o OUT": CLI11 would take the grid's path as LEVEL (even after "--surface=0"); a bare
  // --surface followed by a word that is not a number means the default level, so it moves to the end.
  std::vector<std::string> words(argv, argv + argc);
  auto end = std::find(words.begin() + 1, words.end(), "--");
  for (auto it = words.begin() + 1; it != end; ++it) {
    double number = 0;
    if (*it == "--surface" && it + 1 != end && !(it + 1)->empty() && (*(it + 1))[0] != '-' &&
        !CLI::detail::lexical_cast(*(it + 1), number)) {
      std::rotate(it, it + 1, end);
      break;
    }
  }
  std::vector<char*> args;
  for (std::string& w : words) args.push_back(w.data());
  return cli::parse(app, int(args.size()), args.data());
}

}  // namespace vox::export_tool
