#include "options.h"

#include "../common/cli_app.h"

#include "../common/grid_flags.h"

namespace vox::mpi {

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("scene", opt.scene, "Input scene file (with --bricks)");
  app.add_option("--batch", opt.batch, "File listing scenes, one path a line: each becomes DIR/NAME.vgrid");
  app.add_option("-o,--output", opt.output, "Output manifest (.vgrid) with --bricks, output folder with --batch")
      ->required();
  auto* grid = app.add_option("--grid", opt.grid, "Grid dimensions NX NY NZ")->expected(3);
  auto* res = app.add_option("--res", opt.resolution, "Cells on the longest axis; cells kept as cubic as possible");
  grid->excludes(res);
  app.add_option("--bounds", opt.bounds, "Grid bounds X0 Y0 Z0 X1 Y1 Z1 (default: the scene's bounded primitives)")
      ->expected(6);
  app.add_option("--method", opt.method, "Overlap test: exact (default), sat, bbox, center")
      ->check(CLI::IsMember({"exact", "sat", "bbox", "center"}));
  app.add_flag("--fill", opt.fill,
               "Also mark the empty cells inside the surfaces as solid (with --bricks: rank 0 fills over the "
               "written bricks; the same solid cells as vox-voxelize --fill)");
  app.add_option("--bricks", opt.bricks, "Bricks BX BY BZ of the grid set (one scene)")
      ->expected(3)
      ->check(CLI::Range(1u, kMaxCellsPerAxis));
  app.add_flag("--stats", opt.stats, "Print per-rank work time and peak memory on stderr (rank 0)");
  cli::addCommonOptions(app, opt.common);
  app.footer(
      "Each rank uses the node's cores divided by the ranks on it unless --threads is given. Exit codes (the "
      "same on every rank): 0 ok, 1 usage, 2 bad input (a batch: some scene was bad), 3 cannot write.");
}

std::string modeError(const Options& opt) {
  if (opt.batch.empty() == opt.scene.empty()) return "give either SCENE with --bricks or --batch LIST (see --help)";
  if (opt.batch.empty() && opt.bricks.empty()) return "SCENE needs --bricks BX BY BZ (see --help)";
  return {};
}

VoxelizeOptions voxelizeOptions(const Options& opt) {
  return cli::voxelizeOptionsFromFlags(opt.method, opt.grid, opt.resolution, opt.bounds);
}

// Parses the command line on every rank; only rank 0 prints help, versions and usage errors, the others parse
// silently to the same result. Returns the exit code when the tool should stop now.
std::optional<int> parseOnEveryRank(int rank, int argc, char** argv, Options& opt) {
  CLI::App app{
      "Voxelize over Open MPI ranks: one scene into a grid set (--bricks), or a batch of scenes into one grid "
      "each (--batch). Run as mpirun -n K vox-voxelize-mpi ...",
      "vox-voxelize-mpi"};
  addOptions(app, opt);
  std::optional<int> early;
  if (rank == 0) {
    early = cli::parse(app, argc, argv);
  } else {
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success&) {
      early = 0;
    } catch (const CLI::ParseError&) {
      early = kExitUsage;
    }
  }
  if (early) return early;
  if (const std::string error = modeError(opt); !error.empty()) {
    if (rank == 0) std::fprintf(stderr, "vox-voxelize-mpi: error: %s\n", error.c_str());
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace vox::mpi
