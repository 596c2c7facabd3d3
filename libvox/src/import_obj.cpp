// Wavefront OBJ through tinyobjloader (Debian's 2.0.0rc10, built with float coordinates: real_t = float, so
// coordinates are rounded to single precision). Quirks relied on and worked around:
// - with triangulate = true, quads and polygons come back as triangles (num_face_vertices all 3);
// - it does not reject a face index past the last vertex: it only adds "Vertex indices out of bounds" to its
//   warnings (naming the file's last line), and silently drops such quads; we check every index ourselves and
//   rescan the file for the offending line so the error names it.
#include <tiny_obj_loader.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "vox/error.h"
#include "vox/import.h"

namespace vox {
namespace {

// Finds the first `f` line whose vertex index falls outside the file's `vertexCount` vertices (negative indices
// count back from the vertices read so far). Returns 0 when none is found.
int findBadFaceLine(const std::string& path, long long vertexCount) {
  std::ifstream in(path);
  std::string text;
  int line = 0;
  long long seen = 0;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream words(text);
    std::string keyword;
    if (!(words >> keyword)) continue;
    if (keyword == "v") {
      ++seen;
    } else if (keyword == "f") {
      std::string word;
      while (words >> word) {
        long long i = 0;
        try {
          i = std::stoll(word.substr(0, word.find('/')));
        } catch (const std::exception&) {
          return line;
        }
        const long long zeroBased = i > 0 ? i - 1 : seen + i;
        if (i == 0 || zeroBased < 0 || zeroBased >= vertexCount) return line;
      }
    }
  }
  return 0;
}

[[noreturn]] void failBadIndex(const std::string& path, long long vertexCount) {
  const int line = findBadFaceLine(path, vertexCount);
  if (line > 0) fail<InputError>(path, ":", line, ": face index out of range (", vertexCount, " vertices)");
  fail<InputError>(path, ": face index out of range (", vertexCount, " vertices)");
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

Scene importObj(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail<InputError>(path, ": cannot open OBJ file");

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> objMaterials;
  std::string warn, err;
  const std::string folder = std::filesystem::path(path).parent_path().string();
  const std::string mtlDir = folder.empty() ? std::string("./") : folder + "/";
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &objMaterials, &warn, &err, path.c_str(), mtlDir.c_str(),
                                   /*triangulate=*/true, /*default_vcols_fallback=*/false);
  const long long vertexCount = static_cast<long long>(attrib.vertices.size() / 3);
  if (!ok) fail<InputError>(path, ": ", err.empty() ? std::string("cannot read OBJ file") : trimmed(err));
  if (warn.find("Vertex indices out of bounds") != std::string::npos ||
      warn.find("invalid vertex index") != std::string::npos)
    failBadIndex(path, vertexCount);

  Scene scene;
  for (const auto& m : objMaterials) {
    Material out;
    out.name = m.name;
    out.diffuse = {m.diffuse[0], m.diffuse[1], m.diffuse[2]};
    out.specular = {m.specular[0], m.specular[1], m.specular[2]};
    out.exponent = m.shininess;
    out.indexOfRefraction = m.ior;
    scene.materials.push_back(out);
  }
  const uint32_t defaultMaterial = static_cast<uint32_t>(scene.materials.size());
  bool usesDefault = false;

  for (const auto& shape : shapes) {
    const auto& mesh = shape.mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t n = mesh.num_face_vertices[f];
      if (offset + n > mesh.indices.size()) fail<InputError>(path, ": shape '", shape.name, "': face list is short");
      Vec3 corner[256];
      if (n < 3 || n > 256) fail<InputError>(path, ": shape '", shape.name, "': face with ", n, " vertices");
      for (size_t k = 0; k < n; ++k) {
        const int vi = mesh.indices[offset + k].vertex_index;
        if (vi < 0 || vi >= vertexCount) failBadIndex(path, vertexCount);
        const auto* p = &attrib.vertices[3 * static_cast<size_t>(vi)];
        corner[k] = {p[0], p[1], p[2]};
      }
      uint32_t material = defaultMaterial;
      const int id = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      if (id >= 0 && static_cast<size_t>(id) < objMaterials.size())
        material = static_cast<uint32_t>(id);
      else
        usesDefault = true;
      // Triangulation is on, so n is 3; a fan keeps any other polygon whole should that ever change.
      for (size_t k = 1; k + 1 < n; ++k) scene.triangles.push_back({{corner[0], corner[k], corner[k + 1]}, material});
      offset += n;
    }
  }
  if (usesDefault || scene.materials.empty()) scene.materials.push_back(Material{"default"});

  std::istringstream lines(warn);
  std::string line;
  while (std::getline(lines, line))
    if (!trimmed(line).empty()) scene.warnings.push_back(path + ": " + trimmed(line));
  return scene;
}

}  // namespace vox
