// Tests for the Textures section of grid files (io/grid_section_textures.cpp):
// a textured scene round-trips bit for bit, a scene without textures writes no
// section, and every count, index, size and value in the section is checked
// (the payload is patched and its checksum recomputed, so the section's own
// checks are what refuse it).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "grid_file_util.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::resealed;
using testing::smallGrid;

constexpr size_t kHeader = 32;

Scene texturedScene() {
  Scene scene;
  scene.materials.push_back(Material{"plain"});
  Material m{"tex"};
  m.diffuseTexture = 0;
  scene.materials.push_back(m);
  Texture t;
  t.name = "TEXNAME";
  t.width = 2;
  t.height = 1;
  t.wrapU = TextureWrap::MirroredRepeat;
  t.wrapV = TextureWrap::ClampToEdge;
  t.rgb = {1, 2, 3, 4, 5, 6};
  scene.textures.push_back(t);
  scene.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, 1});
  scene.triangles.push_back({{Vec3{0, 0, 1}, Vec3{1, 0, 1}, Vec3{0, 1, 1}}, 0});
  scene.triangleUVs.push_back({TexCoord{0.1, 1.0 / 3}, TexCoord{-2.5, 1e300}, TexCoord{5e-324, -0.0}});
  scene.triangleUVs.push_back({});
  return scene;
}

template <typename T>
std::string patched(const std::string& bytes, size_t at, T value) {
  std::string out = bytes;
  std::memcpy(out.data() + at, &value, sizeof value);
  return resealed(out);
}

void expectSectionRefused(const std::string& bytes, const std::string& what) {
  try {
    decodeGridFile(bytes, "t.vgrid");
    ADD_FAILURE() << what << ": accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("t.vgrid: ", 0), 0u) << what << ": " << e.what();
  }
}

TEST(GridSectionTextures, RoundTripsBitForBit) {
  const Scene scene = texturedScene();
  const GridFile back = decodeGridFile(encodeGridFile(scene, smallGrid(scene, 2)), "t.vgrid");
  ASSERT_EQ(back.scene.textures.size(), 1u);
  const Texture& t = back.scene.textures[0];
  EXPECT_EQ(t.name, "TEXNAME");
  EXPECT_EQ(t.width, 2u);
  EXPECT_EQ(t.height, 1u);
  EXPECT_EQ(t.wrapU, TextureWrap::MirroredRepeat);
  EXPECT_EQ(t.wrapV, TextureWrap::ClampToEdge);
  EXPECT_EQ(t.rgb, scene.textures[0].rgb);
  EXPECT_EQ(back.scene.materials[0].diffuseTexture, kNoTexture);
  EXPECT_EQ(back.scene.materials[1].diffuseTexture, 0u);
  ASSERT_EQ(back.scene.triangleUVs.size(), 2u);
  for (size_t i = 0; i < 2; ++i)
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(std::memcmp(&back.scene.triangleUVs[i][k], &scene.triangleUVs[i][k], sizeof(TexCoord)), 0);
    }
}

TEST(GridSectionTextures, NoTexturesNoSection) {
  Scene scene = texturedScene();
  const size_t withTextures = encodeGridFile(scene, smallGrid(scene, 2)).size();
  scene.textures.clear();
  scene.materials[1].diffuseTexture = kNoTexture;
  scene.triangleUVs.clear();
  const std::string plain = encodeGridFile(scene, smallGrid(scene, 2));
  EXPECT_EQ(plain.find("TEXNAME"), std::string::npos);
  EXPECT_LT(plain.size(), withTextures);
  EXPECT_TRUE(decodeGridFile(plain, "t.vgrid").scene.textures.empty());
}

TEST(GridSectionTextures, EveryFieldIsChecked) {
  const Scene scene = texturedScene();
  const std::string good = encodeGridFile(scene, smallGrid(scene, 2));
  // Body layout (docs/grid-format.md): u64 T | u32 len "TEXNAME" | u32 w | u32
  // h | u8 wrapU | u8 wrapV | u64 n | n texel bytes | u64 M | (u32 material,
  // u32 texture) * M | u64 N | 6 doubles * N.
  const size_t name = good.find("TEXNAME");
  ASSERT_NE(name, std::string::npos);
  const size_t body = name - 4 - 8;
  const size_t w = name + 7, h = w + 4, wrapU = h + 4, wrapV = wrapU + 1, texels = wrapV + 1;
  const size_t pairs = texels + 8 + 6, material = pairs + 8, texture = material + 4, uvCount = texture + 4;
  const size_t firstUv = uvCount + 8;
  ASSERT_EQ(firstUv + 2 * 6 * 8, good.size());
  EXPECT_NO_THROW(decodeGridFile(resealed(good), "t.vgrid"));

  expectSectionRefused(patched(good, body, uint64_t(0)), "no textures");
  expectSectionRefused(patched(good, body, uint64_t(2)), "two textures");
  expectSectionRefused(patched(good, body, std::numeric_limits<uint64_t>::max()), "absurd texture count");
  expectSectionRefused(patched(good, w, uint32_t(0)), "zero width");
  expectSectionRefused(patched(good, w, uint32_t(3)), "width not matching the texels");
  expectSectionRefused(patched(good, h, uint32_t(kMaxTextureSide + 1)), "too tall");
  expectSectionRefused(patched(good, wrapU, uint8_t(3)), "unknown wrap");
  expectSectionRefused(patched(good, wrapV, uint8_t(255)), "unknown wrap");
  expectSectionRefused(patched(good, texels, uint64_t(5)), "texel count");
  expectSectionRefused(patched(good, texels, uint64_t(1) << 60), "absurd texel count");
  expectSectionRefused(patched(good, pairs, uint64_t(2)), "material pairs past the body");
  expectSectionRefused(patched(good, material, uint32_t(2)), "material out of range");
  expectSectionRefused(patched(good, texture, uint32_t(1)), "texture out of range");
  expectSectionRefused(patched(good, uvCount, uint64_t(1)), "coordinates not one per triangle");
  expectSectionRefused(patched(good, uvCount, uint64_t(3)), "coordinates past the body");
  expectSectionRefused(patched(good, firstUv + 8, std::numeric_limits<double>::quiet_NaN()), "NaN coordinate");
  expectSectionRefused(patched(good, firstUv, std::numeric_limits<double>::infinity()), "infinite coordinate");
  // Cut anywhere inside the section (header and checksum made consistent):
  // refused, never a crash. (Cut right before its tag, the file simply has no
  // section.)
  for (size_t cut = body - 11; cut < good.size(); ++cut) {
    std::string bytes = good.substr(0, cut);
    const uint64_t payload = bytes.size() - kHeader;
    std::memcpy(bytes.data() + 16, &payload, 8);
    expectSectionRefused(resealed(bytes), "cut at " + std::to_string(cut));
  }
}

}  // namespace
}  // namespace vox
