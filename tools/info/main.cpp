// vox-info: statistics of a grid file, as text or JSON, on stdout.
#include <cstdio>
#include <iostream>

#include "../common/cli_app.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/info.h"

int main(int argc, char** argv) {
  std::string path;
  vox::InfoOptions options;
  vox::cli::CommonOptions common;
  CLI::App app{
      "Print the bounds, dimensions, method, primitive counts, occupied cells, references, memory and a "
      "histogram of primitives per cell of a grid file.",
      "vox-info"};
  app.add_option("grid", path, "Grid file (.vgrid)")->required();
  app.add_flag("--json", options.json, "One JSON object instead of text");
  app.add_flag("--cells", options.cells, "With --json: every occupied cell and its primitive ids")->needs("--json");
  app.add_flag("--primitives", options.primitives, "With --json: every primitive in world space")->needs("--json");
  vox::cli::addCommonOptions(app, common);
  if (auto code = vox::cli::parse(app, argc, argv)) return *code;
  return vox::runTool("vox-info", [&] {
    // A set is streamed a layer of bricks at a time, so listing its cells needs no more memory than a layer.
    std::ios::sync_with_stdio(false);
    if (vox::isGridSet(path))
      vox::writeGridSetInfo(std::cout, path, options);
    else
      vox::writeGridInfo(std::cout, vox::readGridFile(path), options);
    std::cout.flush();
    return std::cout ? vox::kExitOk : vox::kExitCannotWrite;
  });
}
