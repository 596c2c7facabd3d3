// loadScene: picks the importer from the file extension (case-insensitive), then rejects non-finite values.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"

namespace vox {

Scene loadScene(const std::string& path, const std::function<bool(double)>& progress) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  // Before any importer opens it: a folder named d.txt must not import as an empty scene, and a FIFO would block.
  requireRegularFile(path, "scene file");
  Scene scene;
  if (ext == ".txt")
    scene = importCourseScene(path, progress);
  else if (ext == ".obj")
    scene = importObj(path, progress);
  else if (ext == ".gltf" || ext == ".glb")
    scene = importGltf(path, progress);
  else if (ext == ".ply")
    scene = importPly(path, progress);
  else
    fail<InputError>(path, ": unknown scene format '", ext, "' (expected .txt, .obj, .gltf, .glb or .ply)");
  validateScene(scene, path);
  return scene;
}

}  // namespace vox
