// Wavefront OBJ scenes through our own reader (obj_reader.h): double-precision coordinates, exact errors.
// Material libraries (`mtllib`) are resolved relative to the OBJ file's folder:
// - a library that does not exist is a warning, and its materials fall back to the default (a downloaded OBJ often
//   comes without its .mtl);
// - a library outside that folder (an absolute path, `..`, or a symbolic link leading out) or one that is not a
//   regular file (a directory, a FIFO, a device) is an InputError naming the OBJ file and line: an OBJ file must not
//   make the tools read other files, and a FIFO would block forever.
// Materials: every material of every library, in file order, then one default white material when a face has none
// (no `usemtl`, or a name that no library defines: a warning), then untextured copies of textured materials for
// faces without texture coordinates.
// Textures (`map_Kd`): resolved against the library's folder and, like libraries, refused outside the OBJ's
// folder; a missing image is a warning (the material keeps Kd). OBJ's v grows upwards, glTF's (and Texture's)
// downwards: the image rows are stored bottom-up instead, so `vt` values stay exactly as written.
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "import/obj_reader.h"
#include "vox/io/texture_decode.h"
#include "vox/core/error.h"
#include "vox/core/huge_pages.h"
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

// The image a `map_Kd` names, decoded with its rows bottom-up (see above), or nullopt with a warning when missing.
std::optional<Texture> loadDiffuseMap(const fs::path& library, const std::string& shown, const MtlDiffuseMap& map,
                                      Scene& scene) {
  const std::string where = shown + ":" + std::to_string(map.line) + ": map_Kd " + quotedWord(map.file);
  std::string name = map.file;
  std::replace(name.begin(), name.end(), '\\', '/');  // paths written on Windows
  std::string file;
  try {
    file = resolveInsideFolder(library.string(), name);
  } catch (const InputError& e) {
    std::string detail = e.what();
    if (detail.rfind(library.string() + ": ", 0) == 0) detail.erase(0, library.string().size() + 2);
    fail<InputError>(where, ": ", detail);
  }
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    scene.warnings.push_back(where + " not found; the material keeps its Kd");
    return std::nullopt;
  }
  Texture t = decodeTexture(readInputFile(file, "texture image"), name, where);
  const size_t row = size_t(t.width) * 3;
  for (uint32_t y = 0; y < t.height / 2; ++y)
    std::swap_ranges(t.rgb.begin() + std::ptrdiff_t(y * row), t.rgb.begin() + std::ptrdiff_t((y + 1) * row),
                     t.rgb.begin() + std::ptrdiff_t((t.height - 1 - y) * row));
  t.name = map.file;
  t.wrapU = t.wrapV = map.clamp ? TextureWrap::ClampToEdge : TextureWrap::Repeat;
  return t;
}

// Reads every library once, appending its materials to scene.materials and its decoded map_Kd images to
// scene.textures; returns each name's last definition.
std::map<std::string, uint32_t> loadLibraries(const std::string& objPath, const ObjData& obj, Scene& scene) {
  std::map<std::string, uint32_t> byName;
  std::set<fs::path> read;
  for (const ObjLibrary& lib : obj.libraries) {
    const auto file = resolveLibrary(objPath, lib, scene);
    if (!file || !read.insert(*file).second) continue;
    // Messages name the library as the OBJ file names it, beside the OBJ file.
    const std::string shown = (fs::path(objPath).parent_path() / lib.name).string();
    const HugeBuffer text = readTextFile(file->string(), "material library", kMaxMtlFileBytes);
    std::vector<MtlDiffuseMap> maps;
    const size_t base = scene.materials.size();
    for (Material& m : parseMtl(text.view(), shown, scene.warnings, &maps)) {
      byName[m.name] = static_cast<uint32_t>(scene.materials.size());
      scene.materials.push_back(std::move(m));
    }
    for (const MtlDiffuseMap& map : maps) {
      std::optional<Texture> t = loadDiffuseMap(*file, shown, map, scene);
      if (!t) continue;
      scene.materials[base + map.material].diffuseTexture = uint32_t(scene.textures.size());
      scene.textures.push_back(std::move(*t));
    }
  }
  return byName;
}

}  // namespace

Scene importObj(const std::string& path, const std::function<bool(double)>& progress) {
  ImportProgress report(progress, path);
  const ObjData obj =
      parseObj(readTextFile(path, "OBJ file", kMaxObjFileBytes, &report).view(), path, kObjChunkBytes, &report);
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
  const bool textured = !scene.textures.empty();
  checkMemory(double(obj.triangles.size()) * (sizeof(Triangle) + (textured ? sizeof(std::array<TexCoord, 3>) : 0)),
              path, "making " + std::to_string(obj.triangles.size()) + " triangles");
  scene.triangles.reserve(obj.triangles.size());
  std::vector<Material> clones;  // untextured copies, materials defaultMaterial + 1 + k
  std::map<uint32_t, uint32_t> cloneOf;
  bool warnedNoTexcoords = false;
  for (size_t i = 0; i < obj.triangles.size(); ++i) {
    report.step(i, 0.9 + 0.1 * double(i) / double(obj.triangles.size()));
    const auto& f = obj.triangles[i];
    uint32_t m = obj.triangleMaterial[i] == kNoObjMaterial ? defaultMaterial : slot[obj.triangleMaterial[i]];
    usesDefault |= m == defaultMaterial;
    std::array<TexCoord, 3> uv{};
    bool hasUv = false;
    if (m != defaultMaterial && scene.materials[m].diffuseTexture != kNoTexture) {
      hasUv = !obj.triangleTexcoords.empty() && obj.triangleTexcoords[i][0] != kNoObjTexcoord;
      if (hasUv) {
        for (int k = 0; k < 3; ++k) uv[size_t(k)] = obj.texcoords[obj.triangleTexcoords[i][size_t(k)]];
      } else {
        if (!warnedNoTexcoords)
          scene.warnings.push_back(path + ": faces of textured material " + quotedWord(scene.materials[m].name) +
                                   " without texture coordinates keep its Kd");
        warnedNoTexcoords = true;
        auto [it, added] = cloneOf.try_emplace(m, defaultMaterial + 1 + uint32_t(clones.size()));
        if (added) {
          clones.push_back(scene.materials[m]);
          clones.back().diffuseTexture = kNoTexture;
        }
        m = it->second;
      }
    }
    scene.triangles.push_back({{obj.vertices[f[0]], obj.vertices[f[1]], obj.vertices[f[2]]}, m});
    if (hasUv) scene.triangleUVs.resize(scene.triangles.size() - 1);
    if (hasUv || !scene.triangleUVs.empty()) scene.triangleUVs.push_back(uv);
  }
  if (usesDefault || scene.materials.empty() || !clones.empty()) scene.materials.push_back(Material{"default"});
  for (Material& c : clones) scene.materials.push_back(std::move(c));
  return scene;
}

}  // namespace vox
