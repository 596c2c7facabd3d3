// Writing voxel meshes (voxel_mesh.h): the bridge to OpenMesh's writers (PLY, OFF, STL) and tinygltf's (glTF);
// OBJ is written here because OpenMesh's OBJ writer puts colours in a .mtl file named after the (temporary) output.
//
// OpenMesh quirks relied on (OpenMesh 9.0):
//  - Its writers read a mesh through the BaseExporter interface, so we hand them the VoxelMesh arrays directly
//    through an adapter instead of building a halfedge mesh: building would cost more than writing, and the
//    adapter never rejects a face.
//  - The PLY writer dereferences exporter.kernel() unconditionally to look for custom properties, so the adapter
//    returns an empty kernel rather than the interface's default null pointer.
//  - The writers log through omlog()/omerr() to the standard streams; the library never prints, so they are muted
//    while writing and failures are reported by the writers' return value.
// tinygltf: TINYGLTF_IMPLEMENTATION is defined once, in import_gltf.cpp.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/exporter/BaseExporter.hh>
#include <OpenMesh/Core/Mesh/BaseKernel.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <tiny_gltf.h>

#include "vox/atomic_file.h"
#include "vox/error.h"
#include "vox/tool.h"
#include "vox/voxel_mesh.h"

namespace vox {

MeshFormat meshFormatFromPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".glb") return MeshFormat::Glb;
  if (ext == ".gltf") return MeshFormat::Gltf;
  fail<InputError>(path, ": unknown mesh format '", ext, "' (expected .ply, .obj, .off, .stl, .glb or .gltf)");
}

namespace {

namespace OM = OpenMesh;

class VoxelMeshExporter : public OM::IO::BaseExporter {
 public:
  explicit VoxelMeshExporter(const VoxelMesh& mesh) : mesh_(mesh) {
    size_t corners = mesh.faceVertices.size();
    edges_ = corners / 2;  // a closed mesh: every edge has two face corners
  }

  OM::Vec3f point(OM::VertexHandle v) const override {
    const Vec3& p = mesh_.positions[size_t(v.idx())];
    return OM::Vec3f(float(p.x), float(p.y), float(p.z));
  }
  OM::Vec3d pointd(OM::VertexHandle v) const override {
    const Vec3& p = mesh_.positions[size_t(v.idx())];
    return OM::Vec3d(p.x, p.y, p.z);
  }
  bool is_point_double() const override { return false; }
  OM::Vec3f normal(OM::VertexHandle) const override { return OM::Vec3f(0, 0, 0); }
  OM::Vec3d normald(OM::VertexHandle) const override { return OM::Vec3d(0, 0, 0); }
  bool is_normal_double() const override { return false; }
  OM::Vec3uc color(OM::VertexHandle) const override { return OM::Vec3uc(255, 255, 255); }
  OM::Vec4uc colorA(OM::VertexHandle) const override { return OM::Vec4uc(255, 255, 255, 255); }
  OM::Vec3ui colori(OM::VertexHandle) const override { return OM::Vec3ui(255, 255, 255); }
  OM::Vec4ui colorAi(OM::VertexHandle) const override { return OM::Vec4ui(255, 255, 255, 255); }
  OM::Vec3f colorf(OM::VertexHandle) const override { return OM::Vec3f(1, 1, 1); }
  OM::Vec4f colorAf(OM::VertexHandle) const override { return OM::Vec4f(1, 1, 1, 1); }
  OM::Vec2f texcoord(OM::VertexHandle) const override { return OM::Vec2f(0, 0); }
  OM::Vec2f texcoord(OM::HalfedgeHandle) const override { return OM::Vec2f(0, 0); }
  OM::Attributes::StatusInfo status(OM::VertexHandle) const override { return {}; }

  unsigned int get_vhandles(OM::FaceHandle f, std::vector<OM::VertexHandle>& vh) const override {
    vh.clear();
    for (uint32_t k = mesh_.faceStart[size_t(f.idx())]; k < mesh_.faceStart[size_t(f.idx()) + 1]; ++k)
      vh.emplace_back(int(mesh_.faceVertices[k]));
    return unsigned(vh.size());
  }
  OM::HalfedgeHandle getHeh(OM::FaceHandle, OM::VertexHandle) const override { return OM::HalfedgeHandle(); }
  unsigned int get_face_texcoords(std::vector<OM::Vec2f>& t) const override {
    t.clear();
    return 0;
  }
  OM::Vec3f normal(OM::FaceHandle f) const override {
    const OM::Vec3d n = normald(f);
    return OM::Vec3f(float(n[0]), float(n[1]), float(n[2]));
  }
  OM::Vec3d normald(OM::FaceHandle f) const override {
    // Newell's method: exact direction for planar polygons, any number of vertices.
    Vec3 n;
    const uint32_t b = mesh_.faceStart[size_t(f.idx())], e = mesh_.faceStart[size_t(f.idx()) + 1];
    for (uint32_t k = b; k < e; ++k) n = n + cross(mesh_.positions[mesh_.faceVertices[k]],
                                                 mesh_.positions[mesh_.faceVertices[k + 1 < e ? k + 1 : b]]);
    n = normalize(n);
    return OM::Vec3d(n.x, n.y, n.z);
  }
  OM::Vec3uc color(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec3uc(c[0], c[1], c[2]);
  }
  OM::Vec4uc colorA(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec4uc(c[0], c[1], c[2], 255);
  }
  OM::Vec3ui colori(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec3ui(c[0], c[1], c[2]);
  }
  OM::Vec4ui colorAi(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec4ui(c[0], c[1], c[2], 255);
  }
  OM::Vec3f colorf(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec3f(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f);
  }
  OM::Vec4f colorAf(OM::FaceHandle f) const override {
    const Rgb8& c = faceColor(f);
    return OM::Vec4f(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f, 1.f);
  }
  OM::Attributes::StatusInfo status(OM::FaceHandle) const override { return {}; }

  OM::Vec3uc color(OM::EdgeHandle) const override { return OM::Vec3uc(0, 0, 0); }
  OM::Vec4uc colorA(OM::EdgeHandle) const override { return OM::Vec4uc(0, 0, 0, 255); }
  OM::Vec3ui colori(OM::EdgeHandle) const override { return OM::Vec3ui(0, 0, 0); }
  OM::Vec4ui colorAi(OM::EdgeHandle) const override { return OM::Vec4ui(0, 0, 0, 255); }
  OM::Vec3f colorf(OM::EdgeHandle) const override { return OM::Vec3f(0, 0, 0); }
  OM::Vec4f colorAf(OM::EdgeHandle) const override { return OM::Vec4f(0, 0, 0, 1); }
  OM::Attributes::StatusInfo status(OM::EdgeHandle) const override { return {}; }

  // Halfedge connectivity is only read by the OM format's writer, which we do not use.
  int get_halfedge_id(OM::VertexHandle) override { return -1; }
  int get_halfedge_id(OM::FaceHandle) override { return -1; }
  int get_next_halfedge_id(OM::HalfedgeHandle) override { return -1; }
  int get_to_vertex_id(OM::HalfedgeHandle) override { return -1; }
  int get_face_id(OM::HalfedgeHandle) override { return -1; }
  OM::Attributes::StatusInfo status(OM::HalfedgeHandle) const override { return {}; }

  const OM::BaseKernel* kernel() override { return &kernel_; }

  size_t n_vertices() const override { return mesh_.vertexCount(); }
  size_t n_faces() const override { return mesh_.faceCount(); }
  size_t n_edges() const override { return edges_; }

  bool is_triangle_mesh() const override { return mesh_.isTriangleMesh(); }
  bool has_face_colors() const override { return mesh_.hasColors(); }
  bool has_face_normals() const override { return false; }

 private:
  const Rgb8& faceColor(OM::FaceHandle f) const {
    static const Rgb8 white{255, 255, 255};
    return mesh_.hasColors() ? mesh_.faceColors[size_t(f.idx())] : white;
  }

  const VoxelMesh& mesh_;
  OM::BaseKernel kernel_;
  size_t edges_ = 0;
};

// Mutes OpenMesh's log streams for its lifetime.
class QuietOpenMesh {
 public:
  QuietOpenMesh() : log_(::omlog().is_enabled()), out_(::omout().is_enabled()), err_(::omerr().is_enabled()) {
    ::omlog().disable();
    ::omout().disable();
    ::omerr().disable();
  }
  ~QuietOpenMesh() {
    if (log_) ::omlog().enable();
    if (out_) ::omout().enable();
    if (err_) ::omerr().enable();
  }

 private:
  bool log_, out_, err_;
};

// Through a stream rather than a file name: OpenMesh's writers do not check their writes, the stream does.
void writeWithOpenMesh(OutputFile& out, const std::string& ext, const VoxelMesh& mesh, OM::IO::Options opt) {
  VoxelMeshExporter exporter(mesh);
  QuietOpenMesh quiet;
  if (!OM::IO::IOManager().write(out.stream(), ext, exporter, opt, 9)) {
    out.flush();  // a write error is the better message
    fail<OutputError>(out.path(), ": cannot write (OpenMesh writer failed)");
  }
}

// Vertices repeated per colour, for formats whose colours live on vertices: corner k of the mesh becomes vertex
// cornerVertex[k], which has position positions[source[v]] and colour colors[v].
struct ColorSplit {
  std::vector<uint32_t> source;
  std::vector<Rgb8> colors;
  std::vector<uint32_t> cornerVertex;
};

ColorSplit splitByColor(const VoxelMesh& mesh) {
  const size_t nc = mesh.faceVertices.size(), nf = mesh.faceCount();
  std::vector<uint64_t> keys(nc);
  auto key = [&](size_t f, uint32_t v) {
    const Rgb8& c = mesh.faceColors[f];
    return (uint64_t(v) << 24) | (uint64_t(c[0]) << 16) | (uint64_t(c[1]) << 8) | c[2];
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nf), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f)
      for (uint32_t k = mesh.faceStart[f]; k < mesh.faceStart[f + 1]; ++k) keys[k] = key(f, mesh.faceVertices[k]);
  });
  std::vector<uint64_t> unique = keys;
  tbb::parallel_sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  ColorSplit split;
  split.source.resize(unique.size());
  split.colors.resize(unique.size());
  for (size_t v = 0; v < unique.size(); ++v) {
    split.source[v] = uint32_t(unique[v] >> 24);
    split.colors[v] = {uint8_t(unique[v] >> 16), uint8_t(unique[v] >> 8), uint8_t(unique[v])};
  }
  split.cornerVertex.resize(nc);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nc), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k)
      split.cornerVertex[k] = uint32_t(std::lower_bound(unique.begin(), unique.end(), keys[k]) - unique.begin());
  });
  return split;
}

// Text built in a string and handed to the OutputFile a megabyte at a time (faster than a std::ostream for many
// short pieces).
class BufferedFile {
 public:
  explicit BufferedFile(OutputFile& out) : out_(out) {}
  void put(std::string_view s) {
    buffer_.append(s);
    if (buffer_.size() > (1 << 20)) flush();
  }
  void number(double x) {
    char tmp[32];
    const auto r = std::to_chars(tmp, tmp + sizeof tmp, x);
    buffer_.append(tmp, r.ptr);
  }
  void number(uint64_t x) {
    char tmp[24];
    const auto r = std::to_chars(tmp, tmp + sizeof tmp, x);
    buffer_.append(tmp, r.ptr);
  }
  void flush() {
    out_.write(buffer_);
    buffer_.clear();
  }

 private:
  OutputFile& out_;
  std::string buffer_;
};

void writeObj(OutputFile& file, const VoxelMesh& mesh) {
  BufferedFile out(file);
  out.put("# voxel mesh written by libvox ");
  out.put(versionString());
  out.put("\n# vertex colours as \"v x y z r g b\" (r g b in [0, 1])\n");
  auto vertex = [&](const Vec3& p) {
    out.put("v ");
    out.number(p.x);
    out.put(" ");
    out.number(p.y);
    out.put(" ");
    out.number(p.z);
  };
  auto faces = [&](auto cornerVertex) {
    for (size_t f = 0; f < mesh.faceCount(); ++f) {
      out.put("f");
      for (uint32_t k = mesh.faceStart[f]; k < mesh.faceStart[f + 1]; ++k) {
        out.put(" ");
        out.number(uint64_t(cornerVertex(k)) + 1);
      }
      out.put("\n");
    }
  };
  if (mesh.hasColors()) {
    const ColorSplit split = splitByColor(mesh);
    for (size_t v = 0; v < split.source.size(); ++v) {
      vertex(mesh.positions[split.source[v]]);
      for (int c = 0; c < 3; ++c) {
        out.put(" ");
        out.number(double(split.colors[v][c]) / 255.0);
      }
      out.put("\n");
    }
    faces([&](uint32_t k) { return split.cornerVertex[k]; });
  } else {
    for (const Vec3& p : mesh.positions) {
      vertex(p);
      out.put("\n");
    }
    faces([&](uint32_t k) { return mesh.faceVertices[k]; });
  }
  out.flush();
}

// glTF COLOR_0 is linear; our face colours are sRGB-encoded display values (IEC 61966-2-1 transfer function).
float srgbToLinear(uint8_t c) {
  const double x = c / 255.0;
  return float(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
}

void writeGltf(OutputFile& out, const VoxelMesh& polygons, bool binary) {
  const VoxelMesh mesh = polygons.isTriangleMesh() ? polygons : triangulateVoxelMesh(polygons);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("libvox ") + versionString() + " vox-export";
  tinygltf::Scene scene;
  scene.name = "voxels";  // also keeps an empty scene a JSON object rather than null
  if (mesh.faceCount() > 0) {
    std::vector<float> pos, col;
    std::vector<uint32_t> idx(mesh.faceVertices.size());
    if (mesh.hasColors()) {
      const ColorSplit split = splitByColor(mesh);
      pos.resize(3 * split.source.size());
      col.resize(3 * split.source.size());
      for (size_t v = 0; v < split.source.size(); ++v) {
        const Vec3& p = mesh.positions[split.source[v]];
        for (int a = 0; a < 3; ++a) {
          pos[3 * v + a] = float(p[a]);
          col[3 * v + a] = srgbToLinear(split.colors[v][a]);
        }
      }
      idx = split.cornerVertex;
    } else {
      pos.resize(3 * mesh.vertexCount());
      for (size_t v = 0; v < mesh.vertexCount(); ++v)
        for (int a = 0; a < 3; ++a) pos[3 * v + a] = float(mesh.positions[v][a]);
      idx = mesh.faceVertices;
    }
    const size_t nv = pos.size() / 3;
    std::vector<double> lo(3, INFINITY), hi(3, -INFINITY);
    for (size_t v = 0; v < nv; ++v)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], double(pos[3 * v + a]));
        hi[a] = std::max(hi[a], double(pos[3 * v + a]));
      }
    tinygltf::Buffer buffer;
    auto append = [&](const void* data, size_t bytes, int target) {
      tinygltf::BufferView view;
      view.buffer = 0;
      view.byteOffset = buffer.data.size();
      view.byteLength = bytes;
      view.target = target;
      const auto* b = static_cast<const unsigned char*>(data);
      buffer.data.insert(buffer.data.end(), b, b + bytes);
      model.bufferViews.push_back(view);
      return int(model.bufferViews.size() - 1);
    };
    auto accessor = [&](int view, int componentType, int type, size_t count) {
      tinygltf::Accessor acc;
      acc.bufferView = view;
      acc.byteOffset = 0;
      acc.componentType = componentType;
      acc.type = type;
      acc.count = count;
      model.accessors.push_back(acc);
      return int(model.accessors.size() - 1);
    };
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    const int posAcc = accessor(append(pos.data(), pos.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                                TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
    model.accessors[size_t(posAcc)].minValues = lo;
    model.accessors[size_t(posAcc)].maxValues = hi;
    prim.attributes["POSITION"] = posAcc;
    if (!col.empty())
      prim.attributes["COLOR_0"] = accessor(append(col.data(), col.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                                            TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
    prim.indices = accessor(append(idx.data(), idx.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
    model.buffers.push_back(std::move(buffer));
    // A matte white material: the default glTF material is fully metallic, which renders the colours nearly black
    // in viewers without an environment map.
    tinygltf::Material material;
    material.name = "voxels";
    material.pbrMetallicRoughness.metallicFactor = 0;
    material.pbrMetallicRoughness.roughnessFactor = 1;
    model.materials.push_back(material);
    prim.material = 0;
    tinygltf::Mesh gm;
    gm.name = "voxels";
    gm.primitives.push_back(prim);
    model.meshes.push_back(gm);
    tinygltf::Node node;
    node.mesh = 0;
    node.name = "voxels";
    model.nodes.push_back(node);
    scene.nodes.push_back(0);
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  tinygltf::TinyGLTF writer;
  // The stream overload embeds the buffer (a data URI in .gltf, the BIN chunk in .glb), as the file overload did
  // with embedBuffers, and leaves the writes to the checked stream.
  if (!writer.WriteGltfSceneToStream(&model, out.stream(), !binary, binary)) {
    out.flush();  // a write error is the better message
    fail<OutputError>(out.path(), ": cannot write (glTF writer failed)");
  }
}

}  // namespace

void writeVoxelMesh(const std::string& path, const VoxelMesh& mesh, bool binary) {
  const MeshFormat format = meshFormatFromPath(path);
  OutputFile out(path);
  OM::IO::Options opt;
  if (binary && (format == MeshFormat::Ply || format == MeshFormat::Stl)) opt += OM::IO::Options::Binary;
  if (mesh.hasColors() && (format == MeshFormat::Ply || format == MeshFormat::Off)) opt += OM::IO::Options::FaceColor;
  switch (format) {
    case MeshFormat::Ply: writeWithOpenMesh(out, ".ply", mesh, opt); break;
    case MeshFormat::Off: writeWithOpenMesh(out, ".off", mesh, opt); break;
    case MeshFormat::Stl:
      writeWithOpenMesh(out, ".stl", mesh.isTriangleMesh() ? mesh : triangulateVoxelMesh(mesh), opt);
      break;
    case MeshFormat::Obj: writeObj(out, mesh); break;
    case MeshFormat::Glb: writeGltf(out, mesh, true); break;
    case MeshFormat::Gltf: writeGltf(out, mesh, false); break;
  }
  out.commit();
}

}  // namespace vox
