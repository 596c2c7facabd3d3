#include "batch.h"

#include <filesystem>
#include <map>

#include "failures.h"
#include "vox/import/import.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"
#include "vox/io/input_file.h"
#include "vox/voxelize/fill.h"

namespace vox::mpi {

std::vector<std::string> readBatchList(const std::string& path) {
  const std::string text = readInputFile(path, "batch list");
  std::vector<std::string> scenes;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    scenes.push_back(line);
  }
  if (scenes.empty()) fail<InputError>(path, ": no scene listed");
  return scenes;
}

std::vector<std::string> batchOutputs(const std::string& list, const std::vector<std::string>& scenes,
                                      const std::string& dir) {
  std::vector<std::string> outputs;
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < scenes.size(); ++i) {
    const std::string name = std::filesystem::path(scenes[i]).stem().string();
    if (name.empty()) fail<InputError>(list, ": line for '", quoteInput(scenes[i]), "' names no file");
    if (!seen.emplace(name, i).second)
      fail<UsageError>(list, ": two scenes would both write ", name, ".vgrid (", quoteInput(scenes[seen[name]]),
                       " and ", quoteInput(scenes[i]), ")");
    outputs.push_back((std::filesystem::path(dir) / (name + ".vgrid")).string());
  }
  return outputs;
}

void makeOutputFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directory(dir, ec);
  if (!std::filesystem::is_directory(dir, ec)) fail<OutputError>(dir, ": cannot create the output folder");
}

void voxelizeOne(const Options& opt, const std::string& scenePath, const std::string& output) {
  const VoxelizeOptions vo = voxelizeOptions(opt);
  checkOutputPath(output, {scenePath});
  const Scene scene = loadScene(scenePath);
  Grid grid = namingScene(scenePath, [&] {
    Grid g = voxelizeScene(scene, vo);
    if (opt.fill) fillSolid(g, scene, FillOptions{vo.memoryLimitBytes, {}, {}, false});
    return g;
  });
  writeGridFile(output, scene, grid);
}

}  // namespace vox::mpi
