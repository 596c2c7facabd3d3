// vox-voxelize's command line: the options parsed into a struct and the voxelizer's options taken from it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "../common/cli.h"
#include "vox/voxelize/voxelize.h"

namespace vox::voxelize_tool {

struct Options {
  std::string scene;
  std::string output;
  std::vector<uint32_t> grid;
  uint32_t resolution = 0;
  std::vector<double> bounds;
  std::string method = "exact";
  bool stats = false;
  bool fill = false;
  std::optional<double> sdf;     // --sdf [HALF]: the signed distance band's half-width in cell widths
  bool fraction = false;         // --fraction: volume fractions of the occupied cells
  std::vector<uint32_t> bricks;  // --bricks BX BY BZ: write a grid set
  cli::CommonOptions common;
};

// Adds the tool's positional argument, options and flags to `app`, bound to `opt`, with the help's footer.
void addOptions(CLI::App& app, Options& opt);

// Parses argv into opt; returns the exit code when the tool should stop now (help, version: 0; bad usage: 1).
std::optional<int> parseCommandLine(int argc, char** argv, Options& opt);

// The voxelizer's options: method, --grid or --res, --bounds, and the memory budget. Throws InputError for an
// unknown method (CLI11 has refused it before).
VoxelizeOptions voxelizeOptions(const Options& opt);

}  // namespace vox::voxelize_tool
