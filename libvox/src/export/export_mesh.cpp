// Writing voxel meshes (voxel_mesh.h): the bridge to OpenMesh's writers (PLY, STL) and tinygltf's (glTF). OBJ is
// written here because OpenMesh's OBJ writer names its .mtl after the (temporary) output; OFF because OpenMesh's
// OFF writer announces per-face colours with a "COFF" header, which means per-vertex colours to every other reader
// (assimp refuses such a file).
//
// What clients read (issue 10; Blender 3.4, MeshLab 2020.09, assimp 5.2 on Debian 12):
//  - PLY: MeshLab reads face colours; Blender's and assimp's importers read vertex colours only. So PLY carries
//    both: the face colours and, per vertex, the colour dominant around it (dominantVertexColors). Vertices stay
//    shared, so the mesh stays closed in every client.
//  - OBJ: vertices shared, faces grouped by "usemtl" (one material per colour) in a .mtl beside the .obj.
//  - glTF: one primitive per colour, all over one shared POSITION accessor, each with its own material. Blender's
//    importer still gives each primitive its own copy of the vertices (its "Merge Vertices" option joins them).
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

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/exporter/BaseExporter.hh>
#include <OpenMesh/Core/Mesh/BaseKernel.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numeric>
#include <tiny_gltf.h>

#include "vox/io/atomic_file.h"
#include "vox/core/error.h"
#include "vox/core/tool.h"
#include "vox/export/voxel_mesh.h"

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
  // `vertexColors`: empty, or one colour per vertex.
  VoxelMeshExporter(const VoxelMesh& mesh, std::vector<Rgb8> vertexColors = {})
      : mesh_(mesh), vertexColors_(std::move(vertexColors)) {
    size_t corners = mesh.faceVertices.size();
    edges_ = corners / 2;  // a closed mesh: every edge has two face corners
  }

  // Asked every 65,536th vertex and face OpenMesh asks for (Ctrl-C while a large mesh is written); may throw.
  const std::function<void()>* check = nullptr;

  OM::Vec3f point(OM::VertexHandle v) const override {
    if (check && (v.idx() & 0xffff) == 0) (*check)();
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
  OM::Vec3uc color(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec3uc(c[0], c[1], c[2]);
  }
  OM::Vec4uc colorA(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec4uc(c[0], c[1], c[2], 255);
  }
  OM::Vec3ui colori(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec3ui(c[0], c[1], c[2]);
  }
  OM::Vec4ui colorAi(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec4ui(c[0], c[1], c[2], 255);
  }
  OM::Vec3f colorf(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec3f(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f);
  }
  OM::Vec4f colorAf(OM::VertexHandle v) const override {
    const Rgb8& c = vertexColor(v);
    return OM::Vec4f(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f, 1.f);
  }
  OM::Vec2f texcoord(OM::VertexHandle) const override { return OM::Vec2f(0, 0); }
  OM::Vec2f texcoord(OM::HalfedgeHandle) const override { return OM::Vec2f(0, 0); }
  OM::Attributes::StatusInfo status(OM::VertexHandle) const override { return {}; }

  unsigned int get_vhandles(OM::FaceHandle f, std::vector<OM::VertexHandle>& vh) const override {
    if (check && (f.idx() & 0xffff) == 0) (*check)();
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
    for (uint32_t k = b; k < e; ++k)
      n = n + cross(mesh_.positions[mesh_.faceVertices[k]], mesh_.positions[mesh_.faceVertices[k + 1 < e ? k + 1 : b]]);
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
  bool has_vertex_colors() const override { return !vertexColors_.empty(); }
  bool has_face_colors() const override { return mesh_.hasColors(); }
  bool has_face_normals() const override { return false; }

 private:
  static constexpr Rgb8 kWhite{255, 255, 255};
  const Rgb8& faceColor(OM::FaceHandle f) const {
    return mesh_.hasColors() ? mesh_.faceColors[size_t(f.idx())] : kWhite;
  }
  const Rgb8& vertexColor(OM::VertexHandle v) const {
    return vertexColors_.empty() ? kWhite : vertexColors_[size_t(v.idx())];
  }

  const VoxelMesh& mesh_;
  std::vector<Rgb8> vertexColors_;
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
void writeWithOpenMesh(OutputFile& out, const std::string& ext, const VoxelMesh& mesh, OM::IO::Options opt,
                       const std::function<void()>& check, std::vector<Rgb8> vertexColors = {}) {
  VoxelMeshExporter exporter(mesh, std::move(vertexColors));
  exporter.check = &check;
  QuietOpenMesh quiet;
  if (!OM::IO::IOManager().write(out.stream(), ext, exporter, opt, 9)) {
    out.flush();  // a write error is the better message
    fail<OutputError>(out.path(), ": cannot write (OpenMesh writer failed)");
  }
}

// Text built in a string and handed to the OutputFile a megabyte at a time (faster than a std::ostream for many
// short pieces).
class BufferedFile {
 public:
  // `check`, asked at every flush (a megabyte), may throw to cancel the write.
  BufferedFile(OutputFile& out, const std::function<void()>& check) : out_(out), check_(check) {}
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
    check_();
    out_.write(buffer_);
    buffer_.clear();
  }

 private:
  OutputFile& out_;
  const std::function<void()>& check_;
  std::string buffer_;
};

void putPosition(BufferedFile& out, const Vec3& p) {
  out.number(p.x);
  out.put(" ");
  out.number(p.y);
  out.put(" ");
  out.number(p.z);
}

// Faces in order of colour (stable: the mesh's order within a colour), for one material or primitive per colour.
std::vector<uint32_t> facesByColor(const VoxelMesh& mesh) {
  std::vector<uint32_t> order(mesh.faceCount());
  std::iota(order.begin(), order.end(), 0u);
  if (mesh.hasColors())
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return mesh.faceColors[a] < mesh.faceColors[b]; });
  return order;
}

std::string materialName(const Rgb8& c) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string name = "vox_";
  for (uint8_t x : c) name += {kHex[x >> 4], kHex[x & 15]};
  return name;
}

// The .mtl of an OBJ: one diffuse material per colour. Kd holds the display (sRGB-encoded) value in [0, 1], as
// the 8-bit colours of PLY and OFF do.
std::string mtlText(const VoxelMesh& mesh) {
  std::vector<Rgb8> colors = mesh.faceColors;
  std::sort(colors.begin(), colors.end());
  colors.erase(std::unique(colors.begin(), colors.end()), colors.end());
  std::string text = std::string("# materials of a voxel mesh written by libvox ") + versionString() + "\n";
  for (const Rgb8& c : colors) {
    text += "\nnewmtl " + materialName(c) + "\nKd";
    for (uint8_t x : c) {
      char tmp[32];
      text += ' ';
      text.append(tmp, std::to_chars(tmp, tmp + sizeof tmp, double(x) / 255.0).ptr);
    }
    text += "\nKa 0 0 0\nKs 0 0 0\nd 1\nillum 1\n";
  }
  return text;
}

// Shared vertices; with colours, faces grouped by colour under "usemtl" and `mtlName` (empty: none) as mtllib.
void writeObj(OutputFile& file, const VoxelMesh& mesh, const std::string& mtlName, const std::function<void()>& check) {
  BufferedFile out(file, check);
  out.put("# voxel mesh written by libvox ");
  out.put(versionString());
  out.put("\n");
  if (!mtlName.empty()) {
    out.put("mtllib ");
    out.put(mtlName);
    out.put("\n");
  }
  for (const Vec3& p : mesh.positions) {
    out.put("v ");
    putPosition(out, p);
    out.put("\n");
  }
  const std::vector<uint32_t> order = facesByColor(mesh);
  for (size_t i = 0; i < order.size(); ++i) {
    const uint32_t f = order[i];
    if (mesh.hasColors() && (i == 0 || mesh.faceColors[f] != mesh.faceColors[order[i - 1]])) {
      out.put("usemtl ");
      out.put(materialName(mesh.faceColors[f]));
      out.put("\n");
    }
    out.put("f");
    for (uint32_t k = mesh.faceStart[f]; k < mesh.faceStart[f + 1]; ++k) {
      out.put(" ");
      out.number(uint64_t(mesh.faceVertices[k]) + 1);
    }
    out.put("\n");
  }
  out.flush();
}

// Geomview OFF: "OFF", counts, vertices, then faces as "n v0 .. vn-1" followed by the face's colour as three
// integers 0..255 (the form MeshLab reads; a "COFF" header would promise per-vertex colours instead).
void writeOff(OutputFile& file, const VoxelMesh& mesh, const std::function<void()>& check) {
  BufferedFile out(file, check);
  out.put("OFF\n");  // no comment line: not every reader skips one
  out.number(uint64_t(mesh.vertexCount()));
  out.put(" ");
  out.number(uint64_t(mesh.faceCount()));
  out.put(" 0\n");
  for (const Vec3& p : mesh.positions) {
    putPosition(out, p);
    out.put("\n");
  }
  for (size_t f = 0; f < mesh.faceCount(); ++f) {
    out.number(uint64_t(mesh.faceSize(f)));
    for (uint32_t k = mesh.faceStart[f]; k < mesh.faceStart[f + 1]; ++k) {
      out.put(" ");
      out.number(uint64_t(mesh.faceVertices[k]));
    }
    if (mesh.hasColors())
      for (uint8_t c : mesh.faceColors[f]) {
        out.put(" ");
        out.number(uint64_t(c));
      }
    out.put("\n");
  }
  out.flush();
}

// glTF colours are linear; our face colours are sRGB-encoded display values (IEC 61966-2-1 transfer function).
double srgbToLinear(uint8_t c) {
  const double x = c / 255.0;
  return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4);
}

// One triangle primitive per colour over one shared POSITION accessor, so the file keeps the mesh's shared
// vertices (no seam cut along colour boundaries), each primitive with a matte material of its colour: glTF
// vertex colours would force one vertex per colour at every seam.
// The glTF model's buffer views over `buffer` (model.buffers[0] once pushed) and accessors.
int appendView(tinygltf::Model& model, tinygltf::Buffer& buffer, const void* data, size_t bytes, int target) {
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.data.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* b = static_cast<const unsigned char*>(data);
  buffer.data.insert(buffer.data.end(), b, b + bytes);
  model.bufferViews.push_back(view);
  return int(model.bufferViews.size() - 1);
}
int addAccessor(tinygltf::Model& model, int view, size_t byteOffset, int componentType, int type, size_t count) {
  tinygltf::Accessor acc;
  acc.bufferView = view;
  acc.byteOffset = byteOffset;
  acc.componentType = componentType;
  acc.type = type;
  acc.count = count;
  model.accessors.push_back(acc);
  return int(model.accessors.size() - 1);
}

// A triangle mesh's vertex indices in order of colour (`order`: the faces so sorted); runs of one colour, which
// become primitives, are idx[runStart[r], runStart[r + 1]).
struct ColorRuns {
  std::vector<uint32_t> order, idx;
  std::vector<size_t> runStart{0};
};
ColorRuns colorRuns(const VoxelMesh& mesh) {
  ColorRuns runs;
  runs.order = facesByColor(mesh);
  runs.idx.reserve(3 * runs.order.size());
  for (size_t i = 0; i < runs.order.size(); ++i) {
    const uint32_t f = runs.order[i];
    if (i > 0 && mesh.hasColors() && mesh.faceColors[f] != mesh.faceColors[runs.order[i - 1]])
      runs.runStart.push_back(runs.idx.size());
    for (uint32_t k = mesh.faceStart[f]; k < mesh.faceStart[f + 1]; ++k) runs.idx.push_back(mesh.faceVertices[k]);
  }
  runs.runStart.push_back(runs.idx.size());
  return runs;
}

// Matte: the default glTF material is fully metallic, which renders colours nearly black in viewers without an
// environment map.
tinygltf::Material matteMaterial(const Rgb8* color) {
  tinygltf::Material material;
  material.pbrMetallicRoughness.metallicFactor = 0;
  material.pbrMetallicRoughness.roughnessFactor = 1;
  if (color) {
    const Rgb8& c = *color;
    material.name = materialName(c);
    material.pbrMetallicRoughness.baseColorFactor = {srgbToLinear(c[0]), srgbToLinear(c[1]), srgbToLinear(c[2]), 1.0};
  } else {
    material.name = "voxels";
  }
  return material;
}

// The triangle mesh (at least one face) as the model's buffer, mesh (a primitive and material per colour) and node.
void addVoxelMesh(tinygltf::Model& model, const VoxelMesh& mesh) {
  const size_t nv = mesh.vertexCount();
  std::vector<float> pos(3 * nv);
  std::vector<double> lo(3, INFINITY), hi(3, -INFINITY);
  for (size_t v = 0; v < nv; ++v)
    for (int a = 0; a < 3; ++a) {
      pos[3 * v + a] = float(mesh.positions[v][a]);
      lo[a] = std::min(lo[a], double(pos[3 * v + a]));
      hi[a] = std::max(hi[a], double(pos[3 * v + a]));
    }
  const ColorRuns runs = colorRuns(mesh);
  tinygltf::Buffer buffer;
  const int posView = appendView(model, buffer, pos.data(), pos.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  const int posAcc = addAccessor(model, posView, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  model.accessors[size_t(posAcc)].minValues = lo;
  model.accessors[size_t(posAcc)].maxValues = hi;
  const int idxView = appendView(model, buffer, runs.idx.data(), runs.idx.size() * sizeof(uint32_t),
                                 TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  model.buffers.push_back(std::move(buffer));

  tinygltf::Mesh gm;
  gm.name = "voxels";
  for (size_t r = 0; r + 1 < runs.runStart.size(); ++r) {
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.attributes["POSITION"] = posAcc;
    prim.indices =
        addAccessor(model, idxView, runs.runStart[r] * sizeof(uint32_t), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                    TINYGLTF_TYPE_SCALAR, runs.runStart[r + 1] - runs.runStart[r]);
    model.materials.push_back(
        matteMaterial(mesh.hasColors() ? &mesh.faceColors[runs.order[runs.runStart[r] / 3]] : nullptr));
    prim.material = int(model.materials.size() - 1);
    gm.primitives.push_back(prim);
  }
  model.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "voxels";
  model.nodes.push_back(node);
}

void writeGltf(OutputFile& out, const VoxelMesh& polygons, bool binary) {
  const VoxelMesh mesh = polygons.isTriangleMesh() ? polygons : triangulateVoxelMesh(polygons);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("libvox ") + versionString() + " vox-export";
  tinygltf::Scene scene;
  scene.name = "voxels";  // also keeps an empty scene a JSON object rather than null
  if (mesh.faceCount() > 0) {
    addVoxelMesh(model, mesh);
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

void writeVoxelMesh(const std::string& path, const VoxelMesh& mesh, bool binary,
                    const std::function<bool(double)>& progress) {
  const MeshFormat format = meshFormatFromPath(path);
  const std::function<void()> check = [&] {
    if (progress && !progress(0)) fail<Error>(path, ": writing cancelled");
  };
  // An OBJ's colours go to a .mtl beside it, written first so that the OBJ never names a missing file. A device
  // (e.g. /dev/stdout) gets no .mtl: there is no folder beside it.
  std::unique_ptr<OutputFile> mtl;
  if (format == MeshFormat::Obj && mesh.hasColors()) {
    std::error_code ec;
    const auto type = std::filesystem::status(path, ec).type();
    if (type != std::filesystem::file_type::character && type != std::filesystem::file_type::fifo) {
      mtl = std::make_unique<OutputFile>(std::filesystem::path(path).replace_extension(".mtl").string());
      mtl->write(mtlText(mesh));
    }
  }
  OutputFile out(path);
  OM::IO::Options opt;
  if (binary && (format == MeshFormat::Ply || format == MeshFormat::Stl)) opt += OM::IO::Options::Binary;
  if (mesh.hasColors() && format == MeshFormat::Ply) {
    opt += OM::IO::Options::FaceColor;
    opt += OM::IO::Options::VertexColor;
  }
  switch (format) {
    case MeshFormat::Ply:
      writeWithOpenMesh(out, ".ply", mesh, opt, check, dominantVertexColors(mesh));
      break;
    case MeshFormat::Off:
      writeOff(out, mesh, check);
      break;
    case MeshFormat::Stl:
      writeWithOpenMesh(
          out, ".stl",
          mesh.isTriangleMesh() ? mesh : triangulateVoxelMesh(mesh, [&](double) { return !progress || progress(0); }),
          opt, check);
      break;
    case MeshFormat::Obj:
      writeObj(out, mesh, mtl ? std::filesystem::path(mtl->path()).filename().string() : std::string(), check);
      if (mtl) mtl->commit();
      break;
    case MeshFormat::Glb:
      writeGltf(out, mesh, true);
      break;
    case MeshFormat::Gltf:
      writeGltf(out, mesh, false);
      break;
  }
  out.commit();
}

}  // namespace vox
