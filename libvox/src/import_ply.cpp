// PLY triangle meshes through OpenMesh 9 (read_mesh into a PolyMesh, then fan triangulation here).
// Quirks relied on:
// - MeshIO.hh must be included before the mesh kernel headers, or no reader gets registered.
// - OpenMesh's PLY reader trusts its header (see checkPlyHeader).
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

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vox/error.h"
#include "vox/import.h"

namespace vox {
namespace {

struct DoubleTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
};
using PlyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

// What the PLY header promises, checked before OpenMesh sees the file: OpenMesh 9 loops forever on a header
// without `end_header` and trusts element counts, so a corrupt header could hang it or make it allocate without
// bound. Counts are checked against the bytes that follow the header (each element needs a minimum number of
// bytes), so OpenMesh's work stays proportional to the file size.
struct PlyHeader {
  long long faces = 0;
};

int plyTypeSize(std::string_view t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

PlyHeader checkPlyHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail<InputError>(path, ": cannot open PLY file");
  in.seekg(0, std::ios::end);
  const long long fileSize = static_cast<long long>(in.tellg());
  in.seekg(0);
  constexpr long long kMaxHeader = 1 << 20;
  std::string head(static_cast<size_t>(std::min(fileSize, kMaxHeader)), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));

  struct Element {
    std::string name;
    long long count = 0;
    long long minBytes = 0;  // per element
  };
  std::vector<Element> elements;
  bool ascii = false;
  size_t pos = 0;
  int lineNumber = 0;
  for (;;) {
    const size_t eol = head.find('\n', pos);
    if (eol == std::string::npos) fail<InputError>(path, ": PLY header has no end_header line");
    std::string line = head.substr(pos, eol - pos);
    pos = eol + 1;
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    auto bad = [&]() { fail<InputError>(path, ":", lineNumber, ": malformed PLY header line '", line, "'"); };
    if (lineNumber == 1) {
      if (w.size() != 1 || w[0] != "ply") fail<InputError>(path, ": not a PLY file (first line is not 'ply')");
    } else if (lineNumber == 2) {
      if (w.size() != 3 || w[0] != "format" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad();
      ascii = w[1] == "ascii";
    } else if (w.empty() || w[0] == "comment" || w[0] == "obj_info") {
      continue;
    } else if (w[0] == "end_header") {
      break;
    } else if (w[0] == "element") {
      if (w.size() != 3) bad();
      Element e{w[1], -1, 0};
      const auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || end != w[2].data() + w[2].size() || e.count < 0) bad();
      elements.push_back(e);
    } else if (w[0] == "property") {
      if (elements.empty()) bad();
      long long bytes = 0;
      if (w.size() == 5 && w[1] == "list" && plyTypeSize(w[2]) && plyTypeSize(w[3]))
        bytes = ascii ? 2 : plyTypeSize(w[2]);
      else if (w.size() == 3 && plyTypeSize(w[1]))
        bytes = ascii ? 2 : plyTypeSize(w[1]);
      else
        bad();
      elements.back().minBytes += bytes;
    } else {
      bad();
    }
  }
  PlyHeader header;
  bool hasVertices = false;
  long double needed = 0;  // wide enough for count * bytes without overflow
  for (const Element& e : elements) {
    needed += static_cast<long double>(e.count) * static_cast<long double>(std::max(e.minBytes, 1LL));
    if (e.name == "vertex") hasVertices = true;
    if (e.name == "face") header.faces = e.count;
  }
  if (!hasVertices) fail<InputError>(path, ": PLY header has no vertex element");
  // ASCII: the last value may end at end of file without a separator.
  if (needed > static_cast<long double>(fileSize - static_cast<long long>(pos)) + 1)
    fail<InputError>(path, ": PLY file is shorter than its header's element counts need (truncated?)");
  return header;
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
  const long long expectedFaces = checkPlyHeader(path).faces;

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
