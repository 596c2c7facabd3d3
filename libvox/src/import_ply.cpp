// PLY triangle meshes through OpenMesh 9 (read_mesh into a PolyMesh, then fan triangulation here).
// Quirks relied on:
// - MeshIO.hh must be included before the mesh kernel headers, or no reader gets registered.
// - OpenMesh's PLY reader trusts its input (see checkPlyFile).
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
#include <cctype>
#include <charconv>
#include <cmath>
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

// OpenMesh 9's PLY reader trusts its input: it loops forever on a header without `end_header` or with a version
// other than 1.0, and a corrupt list count (an ASCII `-222463`, a binary int count of 2^31) makes it read past the
// end and grow a vector until memory runs out. So the whole file is walked here first, header and body, and
// OpenMesh only ever sees a structurally valid PLY: every element present, every list count within the bytes or
// tokens that remain, every ASCII value a finite number.
struct PlyProperty {
  bool list = false;
  std::string countType;  // list only
  std::string valueType;
};
struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

int plyTypeSize(std::string_view t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

bool isPlyFloat(std::string_view t) { return t == "float" || t == "float32" || t == "double" || t == "float64"; }

// Reads an integer of PLY type `t` (not a float type) from `p`, in the file's byte order.
long long readPlyInteger(const unsigned char* p, std::string_view t, bool bigEndian) {
  const int n = plyTypeSize(t);
  unsigned long long u = 0;
  for (int i = 0; i < n; ++i) u |= static_cast<unsigned long long>(p[bigEndian ? n - 1 - i : i]) << (8 * i);
  const bool isSigned = t == "char" || t == "int8" || t == "short" || t == "int16" || t == "int" || t == "int32";
  if (isSigned && n < 8 && (u >> (8 * n - 1)) & 1) return static_cast<long long>(u) - (1LL << (8 * n));
  return static_cast<long long>(u);
}

// Returns the face count of a structurally valid PLY file; throws InputError naming the place otherwise.
long long checkPlyFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail<InputError>(path, ": cannot open PLY file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string data = buffer.str();

  std::vector<PlyElement> elements;
  std::string format;
  size_t pos = 0;
  int lineNumber = 0;
  for (;;) {
    const size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) fail<InputError>(path, ": PLY header has no end_header line");
    std::string line = data.substr(pos, eol - pos);
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
      if (w.size() != 3 || w[0] != "format" || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad();
      format = w[1];
    } else if (w.empty() || w[0] == "comment" || w[0] == "obj_info") {
      continue;
    } else if (w[0] == "end_header") {
      break;
    } else if (w[0] == "element") {
      if (w.size() != 3) bad();
      PlyElement e{w[1], -1, {}};
      const auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || end != w[2].data() + w[2].size() || e.count < 0) bad();
      elements.push_back(e);
    } else if (w[0] == "property") {
      if (elements.empty()) bad();
      if (w.size() == 5 && w[1] == "list" && plyTypeSize(w[2]) && !isPlyFloat(w[2]) && plyTypeSize(w[3]))
        elements.back().properties.push_back({true, w[2], w[3]});
      else if (w.size() == 3 && plyTypeSize(w[1]))
        elements.back().properties.push_back({false, "", w[1]});
      else
        bad();
    } else {
      bad();
    }
  }
  if (std::none_of(elements.begin(), elements.end(), [](const PlyElement& e) { return e.name == "vertex"; }))
    fail<InputError>(path, ": PLY header has no vertex element");

  if (format == "ascii") {
    // Tokens of the body, walked in element order.
    size_t p = pos;
    auto nextToken = [&](const PlyElement& e, long long i) -> std::string_view {
      while (p < data.size() && std::isspace(static_cast<unsigned char>(data[p]))) ++p;
      if (p >= data.size()) fail<InputError>(path, ": PLY file ends inside ", e.name, " ", i, " (truncated?)");
      const size_t start = p;
      while (p < data.size() && !std::isspace(static_cast<unsigned char>(data[p]))) ++p;
      return std::string_view(data).substr(start, p - start);
    };
    auto number = [&](std::string_view token, const PlyElement& e, long long i) {
      double v = 0;
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
      if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(v))
        fail<InputError>(path, ": ", e.name, " ", i, ": bad number '", token, "'");
      return v;
    };
    for (const PlyElement& e : elements)
      for (long long i = 0; i < e.count; ++i)
        for (const PlyProperty& prop : e.properties) {
          if (!prop.list) {
            number(nextToken(e, i), e, i);
            continue;
          }
          const double n = number(nextToken(e, i), e, i);
          // Each list value needs at least two bytes ("0 "), which bounds the count by what remains.
          if (n < 0 || n != std::floor(n) || n > static_cast<double>(data.size() - p))
            fail<InputError>(path, ": ", e.name, " ", i, ": bad list length ", n);
          for (long long k = 0; k < static_cast<long long>(n); ++k) number(nextToken(e, i), e, i);
        }
  } else {
    const bool bigEndian = format == "binary_big_endian";
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    size_t p = pos;
    for (const PlyElement& e : elements) {
      // Fixed-size elements are checked in one step so a large count costs nothing.
      const bool fixed =
          std::none_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& q) { return q.list; });
      if (fixed) {
        size_t size = 0;
        for (const PlyProperty& q : e.properties) size += static_cast<size_t>(plyTypeSize(q.valueType));
        if (size != 0 && static_cast<unsigned long long>(e.count) > (data.size() - p) / size)
          fail<InputError>(path, ": PLY file ends inside the ", e.name, " elements (truncated?)");
        p += size * static_cast<size_t>(e.count);
        continue;
      }
      for (long long i = 0; i < e.count; ++i)
        for (const PlyProperty& q : e.properties) {
          const size_t size = static_cast<size_t>(plyTypeSize(q.list ? q.countType : q.valueType));
          if (data.size() - p < size)
            fail<InputError>(path, ": PLY file ends inside ", e.name, " ", i, " (truncated?)");
          if (!q.list) {
            p += size;
            continue;
          }
          const long long n = readPlyInteger(bytes + p, q.countType, bigEndian);
          p += size;
          const size_t valueSize = static_cast<size_t>(plyTypeSize(q.valueType));
          if (n < 0 || static_cast<unsigned long long>(n) > (data.size() - p) / valueSize)
            fail<InputError>(path, ": ", e.name, " ", i, ": bad list length ", n, " (at byte ", p - size, ")");
          p += valueSize * static_cast<size_t>(n);
        }
    }
  }
  for (const PlyElement& e : elements)
    if (e.name == "face") return e.count;
  return 0;
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
  const long long expectedFaces = checkPlyFile(path);

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
    for (size_t k = 1; k + 1 < corners.size(); ++k)
      scene.triangles.push_back({{corners[0], corners[k], corners[k + 1]}, 0});
  }
  if (static_cast<long long>(mesh.n_faces()) < expectedFaces) {
    scene.warnings.push_back(path + ": " + std::to_string(expectedFaces - static_cast<long long>(mesh.n_faces())) +
                             " of " + std::to_string(expectedFaces) +
                             " faces dropped by OpenMesh (invalid or repeated vertex indices)");
  }
  return scene;
}

}  // namespace vox
