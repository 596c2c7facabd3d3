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
#include <sstream>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <tiny_gltf.h>

#include "vox/error.h"
#include "vox/import.h"
#include "vox/voxel_mesh.h"

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
      OpenMesh::IO::Options opt = OpenMesh::IO::Options::FaceColor;
      ASSERT_TRUE(OpenMesh::IO::read_mesh(m, file, opt));
      EXPECT_TRUE(opt.face_has_color());
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

TEST_F(ExportTest, OffReloadsClosed) {
  const VoxelMesh mesh = buildVoxelMesh(grid_, scene_, FaceMode::Merged, ColorMode::Count);
  writeVoxelMesh(path("mesh.off"), mesh);
  PolyMesh m;
  m.request_face_colors();
  OpenMesh::IO::Options opt = OpenMesh::IO::Options::FaceColor;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(m, path("mesh.off"), opt));
  expectClosedReload(m, mesh);
}

TEST_F(ExportTest, ObjHasVertexColoursAndReloads) {
  const VoxelMesh plain = buildVoxelMesh(grid_, scene_, FaceMode::Exposed, ColorMode::None);
  writeVoxelMesh(path("plain.obj"), plain);
  PolyMesh m;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(m, path("plain.obj")));
  expectClosedReload(m, plain);

  const VoxelMesh colored = buildVoxelMesh(grid_, scene_, FaceMode::Exposed, ColorMode::Count);
  writeVoxelMesh(path("colored.obj"), colored);
  std::ifstream in(path("colored.obj"));
  std::string line;
  size_t vertices = 0, faces = 0;
  std::set<std::array<double, 3>> colors;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream s(line.substr(2));
      double x, y, z, r, g, b;
      ASSERT_TRUE(bool(s >> x >> y >> z >> r >> g >> b)) << line;
      colors.insert({r, g, b});
      ++vertices;
    }
    faces += line.rfind("f ", 0) == 0;
  }
  EXPECT_EQ(faces, colored.faceCount());
  EXPECT_GE(vertices, colored.vertexCount());  // repeated where faces of different colours meet
  std::set<std::array<double, 3>> expected;
  for (const Rgb8& c : colored.faceColors) expected.insert({c[0] / 255.0, c[1] / 255.0, c[2] / 255.0});
  EXPECT_EQ(colors, expected);
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
    const tinygltf::Primitive& prim = model.meshes[0].primitives[0];
    EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
    ASSERT_TRUE(prim.attributes.count("COLOR_0"));
    const float* pos = accessorData<float>(model, prim.attributes.at("POSITION"));
    const float* col = accessorData<float>(model, prim.attributes.at("COLOR_0"));
    const uint32_t* idx = accessorData<uint32_t>(model, prim.indices);
    const size_t n = model.accessors[size_t(prim.indices)].count;
    ASSERT_EQ(n, 3 * tris.faceCount());
    std::vector<Tri> got;
    for (size_t t = 0; t < n / 3; ++t) {
      Tri tri;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = idx[3 * t + k];
        for (int a = 0; a < 3; ++a) tri[k][a] = pos[3 * v + a];
        // Vertices carry their face's colour, linearised from sRGB.
        const Rgb8& c = tris.faceColors[t];
        for (int a = 0; a < 3; ++a) {
          const double s = c[a] / 255.0;
          const double linear = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
          EXPECT_NEAR(col[3 * v + a], linear, 1e-6);
        }
      }
      got.push_back(tri);
    }
    EXPECT_EQ(canonical(got), want);

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
  for (const char* name : {"e.ply", "e.obj", "e.off", "e.glb", "e.gltf"}) EXPECT_NO_THROW(writeVoxelMesh(path(name), mesh)) << name;
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path("e.glb"))) << err;
}

}  // namespace
}  // namespace vox
