// Tests of writeVoxelMesh: every format read back by an independent reader (OpenMesh, tinygltf, the project's glTF
// importer) gives the mesh that was written; errors leave nothing behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <algorithm>
#include <cstring>
#include <iterator>
#include <map>
#include <sstream>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <tiny_gltf.h>

#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/export/voxel_mesh.h"

namespace vox {
namespace {

namespace fs = std::filesystem;
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vox_export_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A random voxel set with edge and corner contacts, holes and tunnels, coloured by primitive count.
    std::mt19937 rng(21);
    std::bernoulli_distribution take(0.45);
    grid_.dims = {9, 7, 6};
    grid_.bounds = {{-2, 0, 1}, {2.5, 3.5, 4}};
    grid_.cellStart = {0};
    for (uint64_t key = 0; key < grid_.cellCount(); ++key)
      if (take(rng)) {
        grid_.cellKeys.push_back(key);
        for (uint32_t p = 0; p <= key % 4; ++p) grid_.primIds.push_back(p);
        grid_.cellStart.push_back(grid_.primIds.size());
      }
    scene_.materials.resize(1);
    scene_.triangles.resize(4);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
  Grid grid_;
  Scene scene_;
};

// OpenMesh refuses faces that would make an edge non-manifold ("complex edge"), so a full reload with no boundary
// edge is itself a check of closedness and manifoldness.
void expectClosedReload(const PolyMesh& m, const VoxelMesh& mesh) {
  EXPECT_EQ(m.n_vertices(), mesh.vertexCount());
  EXPECT_EQ(m.n_faces(), mesh.faceCount());
  size_t boundary = 0;
  for (auto e : m.edges()) boundary += m.is_boundary(e);
  EXPECT_EQ(boundary, 0u);
  for (auto v : m.vertices()) EXPECT_TRUE(m.is_manifold(v));
}

TEST_F(ExportTest, PlyBinaryAndAsciiReloadWithCountsAndFaceColours) {
  for (FaceMode mode : {FaceMode::All, FaceMode::Exposed, FaceMode::Merged}) {
    const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, mode, ColorMode::Count);
    for (bool binary : {true, false}) {
      SCOPED_TRACE(faceModeName(mode) + (binary ? " binary" : " ascii"));
      const std::string file = path("mesh.ply");
      writeVoxelMesh(file, mesh, binary);
      PolyMesh m;
      m.request_face_colors();
      m.request_vertex_colors();
      OpenMesh::IO::Options opt = OpenMesh::IO::Options::FaceColor | OpenMesh::IO::Options::VertexColor;
      ASSERT_TRUE(OpenMesh::IO::read_mesh(m, file, opt));
      EXPECT_TRUE(opt.face_has_color());
      // Vertex colours too, for Blender's and assimp's PLY importers (issue 10): the dominant colour per vertex.
      EXPECT_TRUE(opt.vertex_has_color());
      const std::vector<Rgb8> vertexColors = dominantVertexColors(mesh);
      ASSERT_EQ(m.n_vertices(), vertexColors.size());
      for (size_t v = 0; v < vertexColors.size(); v += 5) {
        const auto c = m.color(PolyMesh::VertexHandle(int(v)));
        EXPECT_EQ((Rgb8{c[0], c[1], c[2]}), vertexColors[v]) << v;
      }
      if (mode == FaceMode::All) {
        EXPECT_EQ(m.n_vertices(), 8 * grid_.cellKeys.size());
        EXPECT_EQ(m.n_faces(), 12 * grid_.cellKeys.size());
      } else {
        expectClosedReload(m, mesh);
      }
      ASSERT_EQ(m.n_faces(), mesh.faceCount());
      for (size_t f = 0; f < mesh.faceCount(); f += 7) {
        const auto c = m.color(PolyMesh::FaceHandle(int(f)));
        EXPECT_EQ((Rgb8{c[0], c[1], c[2]}), mesh.faceColors[f]) << f;
        size_t k = mesh.faceStart[f];
        for (auto v : m.fv_range(PolyMesh::FaceHandle(int(f)))) EXPECT_EQ(uint32_t(v.idx()), mesh.faceVertices[k++]);
      }
      const auto p = m.point(PolyMesh::VertexHandle(3));
      for (int a = 0; a < 3; ++a) EXPECT_FLOAT_EQ(p[a], float(mesh.positions[3][a]));
    }
  }
}

TEST_F(ExportTest, OffHeaderMatchesItsFaceColoursAndReloadsClosed) {
  const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::Count);
  writeVoxelMesh(path("mesh.off"), mesh);
  // "OFF", not "COFF": the colours are per face, after each face's indices (issue 10: assimp refused COFF).
  std::ifstream in(path("mesh.off"));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "OFF");
  size_t nv = 0, nf = 0, ne = 1;
  in >> nv >> nf >> ne;
  EXPECT_EQ(nv, mesh.vertexCount());
  EXPECT_EQ(nf, mesh.faceCount());
  EXPECT_EQ(ne, 0u);
  std::string line;
  std::getline(in, line);
  for (size_t v = 0; v < nv; ++v) {
    double x, y, z;
    ASSERT_TRUE(bool(in >> x >> y >> z));
    EXPECT_EQ(x, mesh.positions[v].x);  // shortest round-trip decimal: exact
    EXPECT_EQ(z, mesh.positions[v].z);
  }
  for (size_t f = 0; f < nf; ++f) {
    size_t n;
    ASSERT_TRUE(bool(in >> n));
    ASSERT_EQ(n, mesh.faceSize(f));
    for (size_t k = 0; k < n; ++k) {
      uint32_t idx;
      in >> idx;
      EXPECT_EQ(idx, mesh.faceVertices[mesh.faceStart[f] + k]);
    }
    int r, g, b;
    ASSERT_TRUE(bool(in >> r >> g >> b));
    EXPECT_EQ((Rgb8{uint8_t(r), uint8_t(g), uint8_t(b)}), mesh.faceColors[f]) << f;
  }
  // Read by hand: OpenMesh 9.0's OFF reader takes face colours only after a "COFF" header, which other readers
  // take as per-vertex colours. MeshLab and assimp read this file (tests/cli/export_meshlab.sh, export_assimp.sh).
  std::string rest;
  EXPECT_FALSE(bool(in >> rest)) << "trailing " << rest;
  const VoxelMesh plain = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::None);
  writeVoxelMesh(path("plain.off"), plain);
  PolyMesh m;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(m, path("plain.off")));
  expectClosedReload(m, plain);
}

TEST_F(ExportTest, ObjSharesVerticesAndGroupsFacesByMaterial) {
  const VoxelMesh plain = buildVoxelMesh(grid_, scene_, FaceMode::Exposed, ColorMode::None);
  writeVoxelMesh(path("plain.obj"), plain);
  EXPECT_EQ(files(), std::vector<std::string>{"plain.obj"});  // no colour, no .mtl
  PolyMesh m;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(m, path("plain.obj")));
  expectClosedReload(m, plain);

  const VoxelMesh colored = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::Count);
  writeVoxelMesh(path("colored.obj"), colored);
  EXPECT_EQ(files(), (std::vector<std::string>{"colored.mtl", "colored.obj", "plain.obj"}));
  // The .mtl: one material per colour, Kd the display colour.
  std::map<std::string, std::array<double, 3>> kd;
  {
    std::ifstream in(path("colored.mtl"));
    std::string line, current;
    while (std::getline(in, line)) {
      std::istringstream s(line);
      std::string key;
      s >> key;
      if (key == "newmtl") s >> current;
      if (key == "Kd") {
        std::array<double, 3> c;
        ASSERT_TRUE(bool(s >> c[0] >> c[1] >> c[2])) << line;
        kd[current] = c;
      }
    }
  }
  std::set<Rgb8> distinct(colored.faceColors.begin(), colored.faceColors.end());
  EXPECT_EQ(kd.size(), distinct.size());
  // The .obj: shared vertices (as many as the mesh has: no seam along colours), every face under the material of
  // its colour, each material used for one run of faces.
  std::ifstream in(path("colored.obj"));
  std::string line, material;
  size_t vertices = 0, mtllibs = 0;
  std::set<std::string> used;
  std::multiset<std::pair<Rgb8, std::vector<uint32_t>>> want, got;
  for (size_t f = 0; f < colored.faceCount(); ++f) {
    const auto first = colored.faceVertices.begin();
    want.insert(
        {colored.faceColors[f], std::vector<uint32_t>(first + colored.faceStart[f], first + colored.faceStart[f + 1])});
  }
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "mtllib") {
      std::string name;
      s >> name;
      EXPECT_EQ(name, "colored.mtl");
      ++mtllibs;
    } else if (key == "v") {
      double x, y, z, extra;
      ASSERT_TRUE(bool(s >> x >> y >> z)) << line;
      EXPECT_FALSE(bool(s >> extra)) << "vertex colours: " << line;
      ++vertices;
    } else if (key == "usemtl") {
      s >> material;
      EXPECT_TRUE(used.insert(material).second) << material << " used for two runs of faces";
      ASSERT_TRUE(kd.count(material)) << material;
    } else if (key == "f") {
      ASSERT_FALSE(material.empty());
      std::vector<uint32_t> face;
      for (uint32_t i; s >> i;) face.push_back(i - 1);
      const auto& c = kd[material];
      auto byte = [](double x) { return uint8_t(std::lround(x * 255)); };
      got.insert({Rgb8{byte(c[0]), byte(c[1]), byte(c[2])}, face});
    }
  }
  EXPECT_EQ(mtllibs, 1u);
  EXPECT_EQ(vertices, colored.vertexCount());
  EXPECT_EQ(used.size(), distinct.size());
  EXPECT_TRUE(got == want);
  PolyMesh mc;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(mc, path("colored.obj")));
  expectClosedReload(mc, colored);
}

TEST_F(ExportTest, StlHasTheTriangles) {
  // Read by hand: OpenMesh's STL reader merges vertices by position, which fuses the separate sheets of surface
  // where voxels meet along an edge, so it cannot reload a voxel mesh faithfully.
  const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::None);
  const VoxelMesh tris = triangulateVoxelMesh(mesh);
  writeVoxelMesh(path("mesh.stl"), mesh, true);
  std::ifstream bin(path("mesh.stl"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(bin)), std::istreambuf_iterator<char>());
  ASSERT_GE(bytes.size(), 84u);
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, tris.faceCount());
  EXPECT_EQ(bytes.size(), 84 + 50 * size_t(count));
  float first[12];
  std::memcpy(first, bytes.data() + 84, sizeof first);
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) EXPECT_EQ(first[3 + 3 * k + a], float(tris.positions[tris.faceVertices[size_t(k)]][a]));

  writeVoxelMesh(path("ascii.stl"), mesh, false);
  std::ifstream text(path("ascii.stl"));
  std::string line;
  size_t facets = 0;
  while (std::getline(text, line)) facets += line.find("facet normal") != std::string::npos;
  EXPECT_EQ(facets, tris.faceCount());
}

// Triangles as sorted lists of float corners, each rotated to start at its smallest corner (keeps orientation).
using Tri = std::array<std::array<float, 3>, 3>;
std::multiset<Tri> canonical(std::vector<Tri> tris) {
  std::multiset<Tri> out;
  for (Tri t : tris) {
    const size_t m = size_t(std::min_element(t.begin(), t.end()) - t.begin());
    std::rotate(t.begin(), t.begin() + ptrdiff_t(m), t.end());
    out.insert(t);
  }
  return out;
}

template <typename T>
const T* accessorData(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
  return reinterpret_cast<const T*>(model.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset);
}

TEST_F(ExportTest, GlbAndGltfReadBackByTinygltfAndImporter) {
  const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::Count);
  const VoxelMesh tris = triangulateVoxelMesh(mesh);
  std::vector<Tri> expected;
  for (size_t f = 0; f < tris.faceCount(); ++f) {
    Tri t;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) t[k][a] = float(tris.positions[tris.faceVertices[3 * f + k]][a]);
    expected.push_back(t);
  }
  const auto want = canonical(expected);
  for (const char* name : {"mesh.glb", "mesh.gltf"}) {
    SCOPED_TRACE(name);
    writeVoxelMesh(path(name), mesh);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool ok = std::string(name).ends_with(".glb") ? loader.LoadBinaryFromFile(&model, &err, &warn, path(name))
                                                        : loader.LoadASCIIFromFile(&model, &err, &warn, path(name));
    ASSERT_TRUE(ok) << err;
    ASSERT_EQ(model.meshes.size(), 1u);
    // One primitive per colour over one shared POSITION accessor holding the mesh's vertices once (issue 10: no
    // seam cut along colours), each with the colour, made linear, as its material's base colour.
    const std::set<Rgb8> distinct(tris.faceColors.begin(), tris.faceColors.end());
    const auto& prims = model.meshes[0].primitives;
    ASSERT_EQ(prims.size(), distinct.size());
    const int posAcc = prims[0].attributes.at("POSITION");
    EXPECT_EQ(model.accessors[size_t(posAcc)].count, tris.vertexCount());
    const float* pos = accessorData<float>(model, posAcc);
    std::vector<Tri> got;
    std::map<Tri, std::array<double, 3>> colorOf;  // exact float triangle -> linear colour of its primitive
    std::set<std::array<double, 3>> seen;
    for (const tinygltf::Primitive& prim : prims) {
      EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
      EXPECT_EQ(prim.attributes.at("POSITION"), posAcc);
      EXPECT_FALSE(prim.attributes.count("COLOR_0"));
      ASSERT_GE(prim.material, 0);
      const auto& base = model.materials[size_t(prim.material)].pbrMetallicRoughness.baseColorFactor;
      const std::array<double, 3> linear{base[0], base[1], base[2]};
      EXPECT_TRUE(seen.insert(linear).second) << "two primitives of one colour";
      const uint32_t* idx = accessorData<uint32_t>(model, prim.indices);
      const size_t n = model.accessors[size_t(prim.indices)].count;
      for (size_t t = 0; t < n / 3; ++t) {
        Tri tri;
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) tri[k][a] = pos[3 * idx[3 * t + k] + a];
        got.push_back(tri);
        colorOf[*canonical({tri}).begin()] = linear;
      }
    }
    EXPECT_EQ(canonical(got), want);
    for (size_t f = 0; f < tris.faceCount(); f += 3) {
      const auto it = colorOf.find(*canonical({expected[f]}).begin());
      ASSERT_NE(it, colorOf.end());
      for (int a = 0; a < 3; ++a) {
        const double s = tris.faceColors[f][size_t(a)] / 255.0;
        EXPECT_NEAR(it->second[size_t(a)], s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4), 1e-12);
      }
    }

    // The project's own importer sees the same triangles.
    const Scene imported = importGltf(path(name));
    std::vector<Tri> importedTris;
    for (const Triangle& t : imported.triangles) {
      Tri tri;
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) tri[k][a] = float(t.v[size_t(k)][a]);
      importedTris.push_back(tri);
    }
    EXPECT_EQ(canonical(importedTris), want);
  }
}

TEST_F(ExportTest, ErrorsLeaveNothingBehind) {
  const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, FaceMode::Exposed, ColorMode::Count);
  EXPECT_THROW(writeVoxelMesh(path("mesh.xyz"), mesh), InputError);
  EXPECT_THROW(writeVoxelMesh(path("missing/mesh.ply"), mesh), OutputError);
  EXPECT_THROW(meshFormatFromPath("mesh"), InputError);
  EXPECT_EQ(meshFormatFromPath("A.GLB"), MeshFormat::Glb);
  EXPECT_TRUE(files().empty());
  if (::geteuid() != 0) {  // root writes anywhere
    fs::create_directories(dir_ / "ro");
    fs::permissions(dir_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(writeVoxelMesh(path("ro/mesh.ply"), mesh), OutputError);
    fs::permissions(dir_ / "ro", fs::perms::owner_all);
    EXPECT_TRUE(fs::is_empty(dir_ / "ro"));
  }
  writeVoxelMesh(path("mesh.ply"), mesh);
  EXPECT_EQ(files(), std::vector<std::string>{"mesh.ply"});
}

TEST_F(ExportTest, EmptyMeshWritesValidFiles) {
  Grid empty;
  empty.dims = {2, 2, 2};
  empty.bounds = {{0, 0, 0}, {1, 1, 1}};
  const VoxelMesh mesh = buildVoxelMesh(empty, scene_, FaceMode::Exposed, ColorMode::Count);
  for (const char* name : {"e.ply", "e.obj", "e.off", "e.glb", "e.gltf"})
    EXPECT_NO_THROW(writeVoxelMesh(path(name), mesh)) << name;
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path("e.glb"))) << err;
}

}  // namespace
}  // namespace vox
