#include "options.h"

#include <algorithm>
#include <cstring>
#include <utility>
#include <vector>

#include "../common/cli_app.h"

#include "../common/grid_flags.h"

namespace vox::voxelize_tool {

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("scene", opt.scene, "Input scene file")->required();
  app.add_option("-o,--output", opt.output, "Output grid file (.vgrid)")->required();
  auto* grid = app.add_option("--grid", opt.grid, "Grid dimensions NX NY NZ")->expected(3);
  auto* res = app.add_option("--res", opt.resolution, "Cells on the longest axis; cells kept as cubic as possible");
  grid->excludes(res);
  app.add_option("--bounds", opt.bounds, "Grid bounds X0 Y0 Z0 X1 Y1 Z1 (default: the scene's bounded primitives)")
      ->expected(6);
  app.add_option("--method", opt.method,
                 "Overlap test: exact (CGAL exact predicates, default), sat (floating-point separating axes), "
                 "bbox (primitive bounding box, superset), center (cell centre in footprint, misses cells)")
      ->check(CLI::IsMember({"exact", "sat", "bbox", "center"}));
  app.add_flag("--fill", opt.fill,
               "Also mark the empty cells inside the surfaces as solid: flood fill for closed meshes, |winding "
               "number| >= 0.5 for open ones; says which on stderr");
  app.add_option_function<std::vector<std::string>>(
         "--sdf",
         [&opt](const std::vector<std::string>& half) {
           // Given bare, CLI11 hands over no value or an empty one: the default band.
           if (half.empty() || half[0].empty()) return void(opt.sdf = 3.0);
           double value = 0;
           if (!CLI::detail::lexical_cast(half[0], value))
             throw CLI::ValidationError("--sdf", "HALF " + half[0] + " is not a number");
           opt.sdf = value;
         },
         "Also store the signed distance (world units, negative inside as --fill decides) at the centre of every "
         "cell within HALF cell widths of the surface (default 3); planes are left out")
      ->expected(0, 1)
      ->type_name("[HALF]");
  app.add_flag("--fraction", opt.fraction,
               "Also store each occupied cell's volume fraction inside the solid (implies --fill, whose solid cells "
               "count 1): exact for closed meshes, balls to 1e-12 of a cell; open or self-overlapping meshes, "
               "ellipsoids and planes are refused");
  app.add_option("--bricks", opt.bricks,
                 "Write a grid set: OUT is a manifest naming the scene file and one brick file per non-empty brick "
                 "of BX x BY x BZ bricks (in a new folder OUT_NAME.bricks/gHEX/ beside it; the old set is removed once "
                 "the new one is in place), voxelized one brick at a time; with "
                 "--fill, the fill runs over all bricks' cells afterwards")
      ->expected(3)
      ->check(CLI::Range(1u, kMaxCellsPerAxis));
  app.add_flag("--stats", opt.stats, "Print statistics (name: value) on stderr");
  cli::addCommonOptions(app, opt.common);
  app.footer("Default grid: about " + std::to_string(int(kCellsPerPrimitive)) +
             " cells per bounded primitive, cubic cells. Exit codes: 0 ok, 1 usage, 2 bad input, 3 cannot write.");
}

VoxelizeOptions voxelizeOptions(const Options& opt) {
  return cli::voxelizeOptionsFromFlags(opt.method, opt.grid, opt.resolution, opt.bounds);
}

namespace {

// "--sdf SCENE -o OUT" and "--sdf 2 SCENE -o OUT": --sdf takes 0 or 1 value, but CLI11 gives it every word that
// follows up to the next option (the scene's path as HALF, or two values). A word that is neither a number nor an
// option cannot be HALF: moved before --sdf, it is the positional scene. Used only when the command line so read is
// valid (parsesQuietly), so that "SCENE --sdf x" keeps its own message ("HALF x is not a number").
std::vector<char*> sceneBeforeSdf(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  const auto plainWord = [](const char* word) {
    double number = 0;
    return word[0] != '\0' && word[0] != '-' && !CLI::detail::lexical_cast(std::string(word), number);
  };
  for (size_t i = 1; i + 1 < args.size(); ++i) {
    if (std::strcmp(args[i], "--") == 0) break;
    if (std::strcmp(args[i], "--sdf") != 0) continue;
    const size_t word = plainWord(args[i + 1])
                            ? i + 1
                            : (i + 2 < args.size() && args[i + 1][0] != '-' && plainWord(args[i + 2]) ? i + 2 : 0);
    if (word == 0) continue;
    std::rotate(args.begin() + ptrdiff_t(i), args.begin() + ptrdiff_t(word), args.begin() + ptrdiff_t(word) + 1);
    i = word;
  }
  return args;
}

bool parsesQuietly(std::vector<char*> args) {
  Options scratch;
  CLI::App app{"", "vox-voxelize"};
  addOptions(app, scratch);
  try {
    app.parse(int(args.size()), args.data());
    return true;
  } catch (const CLI::Error&) {
    return false;
  }
}

}  // namespace

std::optional<int> parseCommandLine(int argc, char** argv, Options& opt) {
  CLI::App app{"Voxelize a scene (.txt course format, .obj, .gltf, .glb, .ply) into a sparse grid file (.vgrid).",
               "vox-voxelize"};
  addOptions(app, opt);
  std::vector<char*> args = sceneBeforeSdf(argc, argv);
  if (!std::equal(args.begin(), args.end(), argv) && !parsesQuietly(args)) args.assign(argv, argv + argc);
  const std::optional<int> exit = cli::parse(app, int(args.size()), args.data());
  opt.fill = opt.fill || opt.fraction;  // a fraction's cells inside are the fill's solid cells (DESIGN.md)
  return exit;
}

}  // namespace vox::voxelize_tool
