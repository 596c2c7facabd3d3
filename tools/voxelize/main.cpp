// vox-voxelize: scene file -> grid file.
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <mutex>

#include "../common/cli.h"
#include "vox/io/atomic_file.h"
#include "vox/core/error.h"
#include "vox/voxelize/fill.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/sets/voxelize_set.h"
#include "vox/voxelize/voxelize.h"

namespace {

struct Options {
  std::string scene;
  std::string output;
  std::vector<uint32_t> grid;
  uint32_t resolution = 0;
  std::vector<double> bounds;
  std::string method = "exact";
  bool stats = false;
  bool fill = false;
  std::vector<uint32_t> bricks;  // --bricks BX BY BZ: write a grid set
  vox::cli::CommonOptions common;
};

// How the fill decided is always said (an open mesh once filled nothing, silently).
void reportFill(const Options& opt, const vox::FillReport& report) {
  if (opt.common.quiet) return;
  std::fprintf(stderr, "vox-voxelize: fill: %s\n", vox::describeFill(report).c_str());
  if (const std::string w = vox::fillWarning(report); !w.empty())
    std::fputs(vox::warningLine("vox-voxelize", opt.scene + ": fill: " + w).c_str(), stderr);
}

// --bricks: the grid set of docs/grid-format.md, brick after brick, then the fill over the bricks' cells.
int runSet(const Options& opt, const vox::Scene& scene, vox::VoxelizeOptions vo,
           std::chrono::steady_clock::time_point start) {
  using namespace vox;
  ProgressBar bar("voxelizing bricks", opt.common.quiet);
  vo.progress = [&](double f) {
    bar.update(f);
    return true;
  };
  VoxelizeStats stats;
  GridSetManifest set;
  ProgressBar fillBar("filling", opt.common.quiet);
  std::once_flag bricksDone;  // the fill calls progress from worker threads
  FillOptions fo;
  fo.memoryLimitBytes = vo.memoryLimitBytes;
  fo.progress = [&](double f) {
    std::call_once(bricksDone, [&] { bar.finish(); });
    fillBar.update(f);
    return true;
  };
  FillReport report;
  try {
    set = writeGridSet(opt.output, scene, vo, {opt.bricks[0], opt.bricks[1], opt.bricks[2]}, &stats,
                       opt.fill ? &fo : nullptr, &report);
    bar.finish();
    fillBar.finish();
  } catch (const LimitError& e) {
    fail<LimitError>(opt.scene, ": ", e.what());
  } catch (const InputError& e) {
    fail<InputError>(opt.scene, ": ", e.what());
  }
  if (opt.fill) reportFill(opt, report);
  if (opt.stats) {
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    uint64_t occupied = 0, references = 0, solid = 0;
    for (const BrickEntry& e : set.entries) {
      occupied += e.occupied;
      references += e.references;
      solid += e.solid;
    }
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr,
                 "triangles: %zu\nspheres: %zu\nplanes: %zu\ndims: %u %u %u\nmethod: %s\nbricks: %u %u %u\n"
                 "brick_files: %zu\ncells_tested: %llu\nexact_fallbacks: %llu\noccupied_cells: %llu\n"
                 "solid_cells: %llu\nreferences: %llu\nvoxelize_seconds: %.6f\ntotal_seconds: %.6f\n"
                 "peak_memory_mb: %.1f\n",
                 scene.triangles.size(), scene.spheres.size(), scene.planes.size(), set.dims[0], set.dims[1],
                 set.dims[2], methodName(set.method).c_str(), set.bricks[0], set.bricks[1], set.bricks[2],
                 set.entries.size(), (unsigned long long)stats.cellsTested, (unsigned long long)stats.exactFallbacks,
                 (unsigned long long)occupied, (unsigned long long)solid, (unsigned long long)references, stats.seconds,
                 total, double(usage.ru_maxrss) / 1024.0);
  }
  return kExitOk;
}

int run(const Options& opt) {
  using namespace vox;
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  VoxelizeOptions vo;
  vo.method = parseMethod(opt.method);
  if (!opt.grid.empty()) vo.dims = std::array<uint32_t, 3>{opt.grid[0], opt.grid[1], opt.grid[2]};
  if (opt.resolution) vo.resolution = opt.resolution;
  if (!opt.bounds.empty())
    vo.bounds = Box{{opt.bounds[0], opt.bounds[1], opt.bounds[2]}, {opt.bounds[3], opt.bounds[4], opt.bounds[5]}};
  vo.memoryLimitBytes = memoryBudgetBytes();

  // Before the scene is read: `-o scene.glb` would destroy the scene.
  checkOutputPath(opt.output, {opt.scene});
  if (!opt.bricks.empty()) checkGridSetOutput(opt.output);  // "-o foo.bricks": refused before any work
  const std::optional<GridSetManifest> previousSet = opt.bricks.empty() ? previousGridSet(opt.output) : std::nullopt;
  const Scene scene = loadScene(opt.scene);
  const double readSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!opt.common.quiet)
    for (const auto& w : scene.warnings) std::fputs(warningLine("vox-voxelize", w).c_str(), stderr);
  if (!opt.bricks.empty()) return runSet(opt, scene, vo, start);
  ProgressBar bar("voxelizing", opt.common.quiet);
  vo.progress = [&](double f) {
    bar.update(f);
    return true;
  };
  VoxelizeStats stats;
  Grid grid;
  try {
    grid = voxelizeScene(scene, vo, &stats);
    bar.finish();
    if (opt.fill) {
      ProgressBar fillBar("filling", opt.common.quiet);
      FillOptions fo;
      fo.memoryLimitBytes = vo.memoryLimitBytes;
      fo.progress = [&](double f) {
        fillBar.update(f);
        return true;
      };
      const FillReport report = fillSolid(grid, scene, fo);
      fillBar.finish();
      reportFill(opt, report);
    }
  } catch (const LimitError& e) {
    fail<LimitError>(opt.scene, ": ", e.what());  // what the scene asks for is named with the scene
  } catch (const InputError& e) {
    fail<InputError>(opt.scene, ": ", e.what());
  }
  if (!grid.outsidePrims.empty() && !opt.common.quiet)
    std::fputs(warningLine("vox-voxelize", opt.scene + ": " + std::to_string(grid.outsidePrims.size()) +
                                               " primitives stick out of the given bounds (traced separately)")
                   .c_str(),
               stderr);
  WriteTimes writeTimes;
  writeGridFile(opt.output, scene, grid, &writeTimes);
  if (previousSet) removeGridSetFiles(opt.output, *previousSet);  // a grid file replaced a set: its files go too

  if (opt.stats) {
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr,
                 "triangles: %zu\nspheres: %zu\nplanes: %zu\ndegenerate_triangles: %llu\ndims: %u %u %u\nmethod: %s\n"
                 "cells_tested: %llu\nexact_fallbacks: %llu\noccupied_cells: %zu\nsolid_cells: %llu\nreferences: %zu\n"
                 "read_seconds: %.6f\nvoxelize_seconds: %.6f\nwrite_seconds: %.6f\nsync_seconds: %.6f\n"
                 "total_seconds: %.6f\npeak_memory_mb: %.1f\n",
                 scene.triangles.size(), scene.spheres.size(), scene.planes.size(),
                 (unsigned long long)stats.degenerateTriangles, grid.dims[0], grid.dims[1], grid.dims[2],
                 methodName(grid.method).c_str(), (unsigned long long)stats.cellsTested,
                 (unsigned long long)stats.exactFallbacks, grid.occupiedCount(), (unsigned long long)grid.solidCount(),
                 grid.referenceCount(), readSeconds, stats.seconds, writeTimes.writeSeconds, writeTimes.syncSeconds,
                 total, double(usage.ru_maxrss) / 1024.0);
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  CLI::App app{"Voxelize a scene (.txt course format, .obj, .gltf, .glb, .ply) into a sparse grid file (.vgrid).",
               "vox-voxelize"};
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
  app.add_option("--bricks", opt.bricks,
                 "Write a grid set: OUT is a manifest naming the scene file and one brick file per non-empty brick "
                 "of BX x BY x BZ bricks (in a new folder OUT_NAME.bricks/gHEX/ beside it; the old set is removed once "
                 "the new one is in place), voxelized one brick at a time; with "
                 "--fill, the fill runs over all bricks' cells afterwards")
      ->expected(3)
      ->check(CLI::Range(1u, vox::kMaxCellsPerAxis));
  app.add_flag("--stats", opt.stats, "Print statistics (name: value) on stderr");
  vox::cli::addCommonOptions(app, opt.common);
  app.footer("Default grid: about " + std::to_string(int(vox::kCellsPerPrimitive)) +
             " cells per bounded primitive, cubic cells. Exit codes: 0 ok, 1 usage, 2 bad input, 3 cannot write.");
  if (auto code = vox::cli::parse(app, argc, argv)) return *code;
  return vox::runTool("vox-voxelize", [&] { return run(opt); });
}
