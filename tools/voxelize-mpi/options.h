// vox-voxelize-mpi's command line: the options parsed into a struct, the combinations CLI11 cannot refuse, and the
// voxelizer's options taken from them. No MPI here (tests/voxelize_mpi_options_test.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "../common/cli.h"
#include "vox/voxelize/voxelize.h"

namespace vox::mpi {

struct Options {
  std::string scene;
  std::string batch;
  std::string output;
  std::vector<uint32_t> grid;
  uint32_t resolution = 0;
  std::vector<double> bounds;
  std::string method = "exact";
  bool fill = false;
  bool stats = false;
  std::vector<uint32_t> bricks;
  cli::CommonOptions common;
};

// Adds the tool's positional argument, options and flags to `app`, bound to `opt`, with the help's footer.
void addOptions(CLI::App& app, Options& opt);

// Parses the command line on every rank; only rank 0 prints help, versions and usage errors, the others parse
// silently to the same result. Returns the exit code when the tool should stop now.
std::optional<int> parseOnEveryRank(int rank, int argc, char** argv, Options& opt);

// What is wrong with a command line CLI11 accepted ("" when nothing): neither or both of SCENE and --batch, or SCENE
// without --bricks. Printed by rank 0 as "vox-voxelize-mpi: error: ..." with exit code 1.
std::string modeError(const Options& opt);

// The voxelizer's options: method, --grid or --res, --bounds, and the memory budget. Throws InputError for an
// unknown method (CLI11 has refused it before).
VoxelizeOptions voxelizeOptions(const Options& opt);

}  // namespace vox::mpi
