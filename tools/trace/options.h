// vox-trace's command line: the options parsed into a struct, the renderer's options and the camera taken from it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "../common/cli.h"
#include "vox/io/grid_file.h"
#include "vox/trace/render.h"

namespace vox::trace_tool {

struct Options {
  std::string grid;
  std::string output;
  std::vector<uint32_t> size;
  std::string mode = "shade";
  std::string accel = "grid";
  uint32_t samples = 1;
  uint32_t bounces = 0;
  double weight = 0.01;
  bool shadeBack = false, noShadows = false;
  std::vector<std::string> filter;  // KIND RADIUS
  bool stats = false;
  std::vector<double> eye, lookAt, up;
  double fov = 0;  // 0: not given
  cli::CommonOptions common;
};

// Adds the tool's positional argument, options and flags to `app`, bound to `opt`, with the help's footer.
void addOptions(CLI::App& app, Options& opt);

// Parses argv into opt; returns the exit code when the tool should stop now (help, version: 0; bad usage: 1).
std::optional<int> parseCommandLine(int argc, char** argv, Options& opt);

// The renderer's options from everything the command line alone decides (all but the camera), checked before the
// grid is read: a bad --size, --samples, --filter or output extension is a UsageError.
RenderOptions renderOptions(const Options& opt);

// The scene's camera (or one framing the grid), with --eye/--look-at, --up and --fov applied.
Camera resolveCamera(const Options& opt, const GridFile& file);

}  // namespace vox::trace_tool
