// Wavefront OBJ scenes through our own reader (obj_reader.h): double-precision coordinates, exact errors.
// Material libraries (`mtllib`) are resolved relative to the OBJ file's folder:
// - a library that does not exist is a warning, and its materials fall back to the default (a downloaded OBJ often
//   comes without its .mtl);
// - a library outside that folder (an absolute path, `..`, or a symbolic link leading out) or one that is not a
//   regular file (a directory, a FIFO, a device) is an InputError naming the OBJ file and line: an OBJ file must not
//   make the tools read other files, and a FIFO would block forever.
// Materials: every material of every library, in file order, then one default white material when a face has none
// (no `usemtl`, or a name that no library defines: a warning).
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "import/obj_reader.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

namespace fs = std::filesystem;

// The library file `lib` names, or nullopt (with a warning) when it does not exist.
std::optional<fs::path> resolveLibrary(const std::string& objPath, const ObjLibrary& lib, Scene& scene) {
  const std::string where = objPath + ":" + std::to_string(lib.line) + ": material library";
  std::string file;
  try {
    file = resolveInsideFolder(objPath, lib.name);  // the one containment check (input_file.h)
  } catch (const InputError& e) {
    std::string detail = e.what();  // "OBJPATH: 'NAME': why", said here with the line
    if (detail.rfind(objPath + ": ", 0) == 0) detail.erase(0, objPath.size() + 2);
    fail<InputError>(where, ": ", detail);
  }
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    scene.warnings.push_back(where + " " + quotedWord(lib.name) +
                             " not found; its materials are drawn in default white");
    return std::nullopt;
  }
  if (!fs::is_regular_file(file, ec)) fail<InputError>(where, " ", quotedWord(lib.name), " is not a regular file");
  return fs::path(file);
}

// Reads every library once, appending its materials to scene.materials; returns each name's last definition.
std::map<std::string, uint32_t> loadLibraries(const std::string& objPath, const ObjData& obj, Scene& scene) {
  std::map<std::string, uint32_t> byName;
  std::set<fs::path> read;
  for (const ObjLibrary& lib : obj.libraries) {
    const auto file = resolveLibrary(objPath, lib, scene);
    if (!file || !read.insert(*file).second) continue;
    // Messages name the library as the OBJ file names it, beside the OBJ file.
    const std::string shown = (fs::path(objPath).parent_path() / lib.name).string();
    const std::string text = readTextFile(file->string(), "material library", kMaxMtlFileBytes);
    for (Material& m : parseMtl(text, shown, scene.warnings)) {
      byName[m.name] = static_cast<uint32_t>(scene.materials.size());
      scene.materials.push_back(std::move(m));
    }
  }
  return byName;
}

}  // namespace

Scene importObj(const std::string& path) {
  const ObjData obj = parseObj(readTextFile(path, "OBJ file", kMaxObjFileBytes), path);
  Scene scene;
  scene.warnings = obj.warnings;
  const std::map<std::string, uint32_t> byName = loadLibraries(path, obj, scene);

  const uint32_t defaultMaterial = static_cast<uint32_t>(scene.materials.size());
  std::vector<uint32_t> slot(obj.materialNames.size(), defaultMaterial);
  for (size_t i = 0; i < slot.size(); ++i) {
    const auto it = byName.find(obj.materialNames[i]);
    if (it != byName.end())
      slot[i] = it->second;
    else
      scene.warnings.push_back(path + ":" + std::to_string(obj.materialLines[i]) + ": material " +
                               quotedWord(obj.materialNames[i]) + " is not defined; default white is used");
  }

  bool usesDefault = false;
  checkMemory(double(obj.triangles.size()) * sizeof(Triangle), path,
              "making " + std::to_string(obj.triangles.size()) + " triangles");
  scene.triangles.reserve(obj.triangles.size());
  for (size_t i = 0; i < obj.triangles.size(); ++i) {
    const auto& f = obj.triangles[i];
    const uint32_t m = obj.triangleMaterial[i] == kNoObjMaterial ? defaultMaterial : slot[obj.triangleMaterial[i]];
    usesDefault |= m == defaultMaterial;
    scene.triangles.push_back({{obj.vertices[f[0]], obj.vertices[f[1]], obj.vertices[f[2]]}, m});
  }
  if (usesDefault || scene.materials.empty()) scene.materials.push_back(Material{"default"});
  return scene;
}

}  // namespace vox
