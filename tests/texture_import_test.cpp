// Tests for texture import: decoding (import/texture_decode.cpp) and glTF base
// colour textures (import/import_gltf.cpp) carried to voxel colours
// (export/cell_color.cpp). Fixtures are made here: a cube whose six faces map
// to six colour blocks of one PNG written with OpenImageIO, in a .gltf with
// external or embedded image and buffer; and Khronos' Duck and BoxTextured from
// the seed scenes.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "vox/io/texture_decode.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/export/cell_color.h"
#include "vox/import/import.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::readAll;

using testing::seed;

using testing::ScratchDir;

void writeAll(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < in.size(); i += 3) {
    uint32_t n = uint8_t(in[i]) << 16;
    if (i + 1 < in.size()) n |= uint8_t(in[i + 1]) << 8;
    if (i + 2 < in.size()) n |= uint8_t(in[i + 2]);
    out += k[(n >> 18) & 63];
    out += k[(n >> 12) & 63];
    out += i + 1 < in.size() ? k[(n >> 6) & 63] : '=';
    out += i + 2 < in.size() ? k[n & 63] : '=';
  }
  return out;
}

// Writes `pixels` (w * h * channels bytes, or 16-bit values when `format` is
// UINT16) as an image file.
void writeImage(const std::string& path, int w, int h, int channels, const void* pixels,
                OIIO::TypeDesc format = OIIO::TypeDesc::UINT8) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << path;
  ASSERT_TRUE(out->open(path, OIIO::ImageSpec(w, h, channels, format)));
  ASSERT_TRUE(out->write_image(format, pixels));
  out->close();
}

// Face f of the unit cube (axis f / 2, at 0 or 1 by f % 2) gets colour kFace[f]
// in a 12x2 texture: block f is texels 2f and 2f+1 of both rows. Texture
// coordinates stay between the block's texel centres, so bilinear sampling
// never leaves the block and each face's voxels get its colour exactly.
constexpr uint8_t kFace[6][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 0}, {255, 0, 255}, {200, 100, 50}};

std::string cubePng(const ScratchDir& dir) {
  std::vector<uint8_t> px(12 * 2 * 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 12; ++x) std::memcpy(&px[(y * 12 + x) * 3], kFace[x / 2], 3);
  writeImage(dir.file("cube.png"), 12, 2, 3, px.data());
  return readAll(dir.file("cube.png"));
}

// The cube's binary buffer: 24 positions, 24 texture coordinates (floats), 36
// uint16 indices.
std::string cubeBuffer() {
  std::vector<float> pos, uv;
  std::vector<uint16_t> idx;
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const float at = float(f % 2);
    const float u0 = (2 * f + 0.5f) / 12, u1 = (2 * f + 1.5f) / 12;
    const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (const auto& k : corner) {
      float p[3];
      p[a] = at;
      p[b] = float(k[0]);
      p[c] = float(k[1]);
      pos.insert(pos.end(), p, p + 3);
      uv.push_back(u0 + (u1 - u0) * float(k[0]));
      uv.push_back(0.25f + 0.5f * float(k[1]));
    }
    const uint16_t base = uint16_t(4 * f);
    for (int i : {0, 1, 2, 0, 2, 3}) idx.push_back(uint16_t(base + i));
  }
  std::string bytes(reinterpret_cast<const char*>(pos.data()), pos.size() * 4);
  bytes.append(reinterpret_cast<const char*>(uv.data()), uv.size() * 4);
  bytes.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 2);
  return bytes;
}

// A .gltf of the cube; `bufferUri` and `imageUri` are written as given.
// `samplerJson` replaces the sampler.
std::string cubeGltf(const std::string& bufferUri, const std::string& imageUri,
                     const std::string& samplerJson = R"({"wrapS": 33071, "wrapT": 33648})",
                     const std::string& uvAttribute = R"(, "TEXCOORD_0": 1)") {
  std::ostringstream j;
  j << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0)"
    << uvAttribute << R"(}, "indices": 2, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "textures": [{"sampler": 0, "source": 0}], "samplers": [)"
    << samplerJson << R"(],
  "images": [{"uri": ")"
    << imageUri << R"("}],
  "buffers": [{"uri": ")"
    << bufferUri << R"(", "byteLength": 552}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 288}, {"buffer": 0, "byteOffset": 288, "byteLength": 192},
                  {"buffer": 0, "byteOffset": 480, "byteLength": 72}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 24, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5126, "count": 24, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"}]})";
  return j.str();
}

std::array<int, 3> bytesOf(const Vec3& c) {
  return {int(std::lround(c.x * 255)), int(std::lround(c.y * 255)), int(std::lround(c.z * 255))};
}

// Voxelizes the cube at 4^3 and checks that every cell inside a face (not on
// the cube's edges) has that face's colour, byte for byte.
void expectCubeFaceColours(const Scene& scene) {
  VoxelizeOptions options;
  options.dims = std::array<uint32_t, 3>{4, 4, 4};
  const Grid grid = voxelizeScene(scene, options);
  int checked = 0;
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) {
    const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
    int face = -1, faces = 0;
    for (int a = 0; a < 3; ++a)
      for (int side = 0; side < 2; ++side)
        if (ijk[a] == (side ? 3u : 0u)) face = 2 * a + side, ++faces;
    if (faces != 1) continue;  // on an edge or corner of the cube: two faces mix
    const auto got = bytesOf(cellMaterialColor(grid, scene, c));
    EXPECT_EQ(got, (std::array<int, 3>{kFace[face][0], kFace[face][1], kFace[face][2]}))
        << "cell " << ijk[0] << " " << ijk[1] << " " << ijk[2] << " face " << face;
    ++checked;
  }
  EXPECT_EQ(checked, 6 * 4);  // 2x2 interior cells per face
}

TEST(TextureImport, TexturedGltfCubeExternalFiles) {
  ScratchDir dir("tex_cube");
  cubePng(dir);
  writeAll(dir.file("cube.bin"), cubeBuffer());
  writeAll(dir.file("cube.gltf"), cubeGltf("cube.bin", "cube.png"));
  const Scene scene = importGltf(dir.file("cube.gltf"));
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].width, 12u);
  EXPECT_EQ(scene.textures[0].height, 2u);
  EXPECT_EQ(scene.textures[0].wrapU, TextureWrap::ClampToEdge);
  EXPECT_EQ(scene.textures[0].wrapV, TextureWrap::MirroredRepeat);
  EXPECT_EQ(scene.textures[0].name, "cube.png");
  EXPECT_EQ(scene.materials[0].diffuseTexture, 0u);
  ASSERT_EQ(scene.triangleUVs.size(), 12u);
  EXPECT_EQ(scene.triangleUVs[0][1].u,
            double((0.5f + (1.5f - 0.5f)) / 12));  // floats read exactly
  for (const std::string& w : scene.warnings) ADD_FAILURE() << "warning: " << w;
  expectCubeFaceColours(scene);
}

TEST(TextureImport, TexturedGltfCubeEmbeddedDataUris) {
  ScratchDir dir("tex_cube_embedded");
  const std::string png = cubePng(dir);
  std::filesystem::remove(dir.file("cube.png"));
  writeAll(dir.file("cube.gltf"), cubeGltf("data:application/octet-stream;base64," + base64(cubeBuffer()),
                                           "data:image/png;base64," + base64(png)));
  const Scene scene = importGltf(dir.file("cube.gltf"));
  ASSERT_EQ(scene.textures.size(), 1u);
  expectCubeFaceColours(scene);
}

TEST(TextureImport, PrimitiveWithoutTexcoordsKeepsTheFactor) {
  ScratchDir dir("tex_cube_nouv");
  cubePng(dir);
  writeAll(dir.file("cube.bin"), cubeBuffer());
  writeAll(dir.file("cube.gltf"), cubeGltf("cube.bin", "cube.png", "{}", ""));
  const Scene scene = importGltf(dir.file("cube.gltf"));
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("no TEXCOORD_0"), std::string::npos) << scene.warnings[0];
  const uint32_t m = scene.triangles[0].material;
  ASSERT_LT(m, scene.materials.size());
  EXPECT_EQ(scene.materials[m].diffuseTexture, kNoTexture);
  EXPECT_NO_THROW(validateScene(scene, "cube.gltf"));
}

TEST(TextureImport, BadTexturesAreErrorsNamingTheImage) {
  ScratchDir dir("tex_bad");
  const std::string png = cubePng(dir);
  writeAll(dir.file("cube.bin"), cubeBuffer());
  writeAll(dir.file("cut.png"), png.substr(0, png.size() / 2));
  writeAll(dir.file("a.gltf"), cubeGltf("cube.bin", "cut.png"));
  try {
    importGltf(dir.file("a.gltf"));
    FAIL() << "truncated PNG accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.gltf: image 0"), std::string::npos) << e.what();
  }
  writeAll(dir.file("b.gltf"), cubeGltf("cube.bin", "cube.png", R"({"wrapS": 1234})"));
  EXPECT_THROW(importGltf(dir.file("b.gltf")), InputError);
  writeAll(dir.file("junk.png"), std::string(100, 'x'));
  writeAll(dir.file("c.gltf"), cubeGltf("cube.bin", "junk.png"));
  EXPECT_THROW(importGltf(dir.file("c.gltf")), InputError);
}

TEST(TextureImport, DecodeGreyAlphaSixteenBitAndFloat) {
  ScratchDir dir("tex_decode");
  const uint8_t ga[4] = {10, 255, 200, 0};  // grey + alpha: alpha dropped, grey spread
  writeImage(dir.file("ga.png"), 2, 1, 2, ga);
  Texture t = decodeTexture(readAll(dir.file("ga.png")), "ga.png", "ga");
  EXPECT_EQ(t.rgb, (std::vector<uint8_t>{10, 10, 10, 200, 200, 200}));
  const uint16_t deep[3] = {65535, 32768, 0};
  writeImage(dir.file("d.png"), 1, 1, 3, deep, OIIO::TypeDesc::UINT16);
  t = decodeTexture(readAll(dir.file("d.png")), "d.png", "d");
  EXPECT_EQ(t.rgb, (std::vector<uint8_t>{255, 128, 0}));
  const float lin[3] = {1.0f, 0.5f, 0.0f};  // linear light, encoded to sRGB
  writeImage(dir.file("f.exr"), 1, 1, 3, lin, OIIO::TypeDesc::FLOAT);
  t = decodeTexture(readAll(dir.file("f.exr")), "f.exr", "f");
  EXPECT_EQ(t.rgb, (std::vector<uint8_t>{255, 188, 0}));
  const uint8_t rgb[3] = {1, 2, 3};
  writeImage(dir.file("j.jpg"), 1, 1, 3, rgb);
  const std::string jpg = readAll(dir.file("j.jpg"));
  EXPECT_EQ(decodeTexture(jpg, "", "j").width, 1u);
  EXPECT_THROW(decodeTexture(jpg.substr(0, jpg.size() / 2), "", "j"), InputError);
  EXPECT_THROW(decodeTexture("", "", "e"), InputError);
  EXPECT_THROW(decodeTexture("just text", "x.unknownext", "e"), InputError);
}

// Khronos' Duck: one texture, mostly yellow. Imported as a factor only it came
// out white (issue 11).
TEST(TextureImport, TheDuckIsYellow) {
  const Scene gltf = importGltf(seed("gltf/Duck/glTF/Duck.gltf"));
  const Scene glb = importGltf(seed("gltf/Duck/glTF-Binary/Duck.glb"));
  ASSERT_EQ(gltf.textures.size(), 1u);
  ASSERT_EQ(glb.textures.size(), 1u);
  EXPECT_EQ(gltf.textures[0].rgb,
            glb.textures[0].rgb);  // external file and GLB bufferView decode alike
  ASSERT_EQ(gltf.triangleUVs.size(), gltf.triangles.size());
  VoxelizeOptions options;
  options.resolution = 24;
  const Grid grid = voxelizeScene(gltf, options);
  size_t yellow = 0;
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) {
    const Vec3 col = cellMaterialColor(grid, gltf, c);
    yellow += col.x > 0.9 && col.y > 0.6 && col.y < 0.95 && col.z < 0.15;
    // The GLB's triangles and texture coordinates are the same: so is every
    // colour.
    EXPECT_EQ(bytesOf(col), bytesOf(cellMaterialColor(grid, glb, c)));
  }
  EXPECT_GT(double(yellow), 0.8 * double(grid.cellKeys.size())) << yellow << " of " << grid.cellKeys.size();
}

// BoxTextured three ways: external PNG, data URI, GLB bufferView: the same
// texels.
TEST(TextureImport, BoxTexturedEveryImageSource) {
  const Scene a = importGltf(seed("gltf/BoxTextured/glTF/BoxTextured.gltf"));
  const Scene b = importGltf(seed("gltf/BoxTextured/glTF-Embedded/BoxTextured.gltf"));
  const Scene c = importGltf(seed("gltf/BoxTextured/glTF-Binary/BoxTextured.glb"));
  ASSERT_EQ(a.textures.size(), 1u);
  ASSERT_EQ(b.textures.size(), 1u);
  ASSERT_EQ(c.textures.size(), 1u);
  EXPECT_GT(a.textures[0].rgb.size(), 0u);
  EXPECT_EQ(a.textures[0].rgb, b.textures[0].rgb);
  EXPECT_EQ(a.textures[0].rgb, c.textures[0].rgb);
}

// OBJ map_Kd: v grows upwards in OBJ, so the image's top row colours the top of
// the quad.
TEST(TextureImport, ObjMapKd) {
  ScratchDir dir("tex_obj");
  const uint8_t px[6] = {255, 0, 0, 0, 0, 255};  // 1x2: top row red, bottom row blue
  writeImage(dir.file("tex.png"), 1, 2, 3, px);
  writeAll(dir.file("q.mtl"),
           "newmtl t\nmap_Kd -clamp on -s 1 1 1 -bm 1 "
           "tex.png\nnewmtl gone\nKd 0 1 0\n"
           "map_Kd missing.png\n");
  writeAll(dir.file("q.obj"),
           "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3 4/4\nf 1 2 5\n"
           "usemtl gone\nf 2 3 5\n");
  const Scene scene = importObj(dir.file("q.obj"));
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].wrapU, TextureWrap::ClampToEdge);
  EXPECT_EQ(scene.materials[0].diffuseTexture, 0u);
  EXPECT_EQ(scene.materials[0].diffuse.x,
            1);  // no Kd: white, so the texture shows unchanged
  EXPECT_EQ(scene.materials[1].diffuseTexture,
            kNoTexture);  // its image is missing: Kd stays
  ASSERT_EQ(scene.triangleUVs.size(), 4u);
  EXPECT_EQ(scene.triangleUVs[0][2].v, 1);  // as written
  // The face without vt has an untextured copy of the material; both remarks
  // are warnings.
  EXPECT_EQ(scene.materials[scene.triangles[2].material].diffuseTexture, kNoTexture);
  EXPECT_EQ(scene.warnings.size(), 2u);
  Scene quad = scene;  // only the textured quad
  quad.triangles.resize(2);
  quad.triangleUVs.resize(2);
  VoxelizeOptions options;
  options.bounds = Box{{0, 0, -0.5}, {1, 1, 0.5}};
  options.dims = std::array<uint32_t, 3>{1, 2, 1};
  const Grid grid = voxelizeScene(quad, options);
  ASSERT_EQ(grid.cellKeys.size(), 2u);
  const Vec3 bottom = cellMaterialColor(grid, quad, 0), top = cellMaterialColor(grid, quad, 1);
  EXPECT_GT(top.x, 0.9);
  EXPECT_LT(top.z, 0.7);
  EXPECT_GT(bottom.z, 0.9);
  EXPECT_LT(bottom.x, 0.7);
  // A texture outside the OBJ's folder is refused.
  writeAll(dir.file("e.mtl"), "newmtl t\nmap_Kd ../../etc/passwd\n");
  writeAll(dir.file("e.obj"), "mtllib e.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl t\nf 1 2 3\n");
  EXPECT_THROW(importObj(dir.file("e.obj")), InputError);
}

}  // namespace
}  // namespace vox
