// PLY triangle meshes through OpenMesh 9 (read_mesh into a PolyMesh, then fan triangulation here).
// Quirks relied on:
// - MeshIO.hh must be included before the mesh kernel headers, or no reader gets registered.
// - OpenMesh's importer drops faces with an invalid or repeated vertex index (it prints to omerr and goes on) and
//   re-adds non-manifold faces with duplicated vertices, so every valid face survives. We compare the face count
//   with the header's `element face N` to report dropped faces as a warning.
// - OpenMesh prints its complaints to std::cerr through omerr()/omlog(); the library must not print, so they are
//   muted while reading (global streams: not thread-safe, like OpenMesh's own IO manager).
// OpenMesh's Property.hh trips GCC 12's -Wmaybe-uninitialized (a false positive seen with -O1 and sanitizers) in
// code instantiated here, so the warning is off for this file.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "vox/error.h"
#include "vox/import.h"

namespace vox {
namespace {

struct DoubleTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
};
using PlyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

// The face count in the PLY header, or -1 when the header cannot be read.
long long headerFaceCount(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) return -1;
  for (int guard = 0; guard < 10000 && std::getline(in, line); ++guard) {
    std::istringstream words(line);
    std::string a, b;
    long long n = -1;
    words >> a;
    if (a == "end_header") break;
    if (a == "element" && (words >> b >> n) && b == "face") return n;
  }
  return -1;
}

// Mutes an OpenMesh stream for the lifetime of the guard, restoring its previous state.
class MuteStream {
 public:
  explicit MuteStream(OpenMesh::mostream& s) : stream_(s), wasEnabled_(s.is_enabled()) { stream_.disable(); }
  ~MuteStream() {
    if (wasEnabled_) stream_.enable();
  }
  MuteStream(const MuteStream&) = delete;
  MuteStream& operator=(const MuteStream&) = delete;

 private:
  OpenMesh::mostream& stream_;
  bool wasEnabled_;
};

}  // namespace

Scene importPly(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail<InputError>(path, ": cannot open PLY file");
  const long long expectedFaces = headerFaceCount(path);
  if (expectedFaces < 0) fail<InputError>(path, ": not a PLY file (no 'ply' header with an 'element face' line)");

  PlyMesh mesh;
  bool ok = false;
  {
    MuteStream e(::omerr()), l(::omlog()), o(::omout());
    OpenMesh::IO::Options options;
    ok = OpenMesh::IO::read_mesh(mesh, path, options);
  }
  if (!ok) fail<InputError>(path, ": OpenMesh cannot read this PLY file (malformed or truncated)");

  Scene scene;
  scene.materials.push_back(Material{"default"});
  scene.triangles.reserve(mesh.n_faces());
  std::vector<Vec3> corners;
  for (const auto& face : mesh.faces()) {
    corners.clear();
    for (const auto& v : face.vertices()) {
      const auto& p = mesh.point(v);
      corners.push_back({p[0], p[1], p[2]});
    }
    for (size_t k = 1; k + 1 < corners.size(); ++k) scene.triangles.push_back({{corners[0], corners[k], corners[k + 1]}, 0});
  }
  if (static_cast<long long>(mesh.n_faces()) < expectedFaces) {
    scene.warnings.push_back(path + ": " + std::to_string(expectedFaces - static_cast<long long>(mesh.n_faces())) +
                             " of " + std::to_string(expectedFaces) +
                             " faces dropped by OpenMesh (invalid or repeated vertex indices)");
  }
  return scene;
}

}  // namespace vox
