// vox-export's command line: the options parsed into a struct.
#pragma once

#include <optional>
#include <string>

#include "../common/cli.h"

namespace vox::export_tool {

struct Options {
  std::string grid;
  std::string output;
  std::string faces = "exposed";
  std::string color = "count";
  bool ascii = false;
  bool stats = false;
  std::optional<double> surface;  // --surface [LEVEL]: the level set of the grid's distances instead of the voxels
  cli::CommonOptions common;
};

// Adds the tool's positional argument, options and flags to `app`, bound to `opt`, with the help's footer.
void addOptions(CLI::App& app, Options& opt);

// Parses argv into opt; returns the exit code when the tool should stop now (help, version: 0; bad usage: 1).
std::optional<int> parseCommandLine(int argc, char** argv, Options& opt);

}  // namespace vox::export_tool
