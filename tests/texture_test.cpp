// Tests for image textures of the scene model (core/texture.cpp): the sRGB
// transfer function, bilinear sampling with each wrap mode, and validation.
#include "vox/core/texture.h"

#include <gtest/gtest.h>

#include "vox/core/error.h"
#include "vox/core/scene.h"

namespace vox {
namespace {

Texture texture(uint32_t w, uint32_t h, std::vector<uint8_t> rgb, TextureWrap wrap = TextureWrap::Repeat) {
  Texture t;
  t.width = w;
  t.height = h;
  t.rgb = std::move(rgb);
  t.wrapU = t.wrapV = wrap;
  return t;
}

TEST(Texture, SrgbRoundTripsEveryByte) {
  EXPECT_EQ(srgbToLinear(0), 0);
  EXPECT_EQ(srgbToLinear(255), 1);
  EXPECT_NEAR(srgbToLinear(188), 0.5029, 1e-4);  // the familiar "half grey"
  for (int b = 0; b < 256; ++b) {
    EXPECT_EQ(std::lround(linearToSrgb(srgbToLinear(uint8_t(b))) * 255), b);
    if (b > 0) {
      EXPECT_GT(srgbToLinear(uint8_t(b)), srgbToLinear(uint8_t(b - 1)));
    }
  }
  EXPECT_EQ(linearToSrgb(-1), 0);
  EXPECT_EQ(linearToSrgb(2), 1);
  EXPECT_EQ(linearToSrgb(std::nan("")), 0);
}

// Two texels in a row: black then white (encoded 255 = linear 1).
TEST(Texture, BilinearBetweenTexelCentresAndWrapModes) {
  const std::vector<uint8_t> bw{0, 0, 0, 255, 255, 255};
  const Texture repeat = texture(2, 1, bw, TextureWrap::Repeat);
  const Texture clamp = texture(2, 1, bw, TextureWrap::ClampToEdge);
  const Texture mirror = texture(2, 1, bw, TextureWrap::MirroredRepeat);
  // Texel centres are exact; half-way between them is the linear mean.
  EXPECT_EQ(sampleTexture(repeat, {0.25, 0.5}).x, 0);
  EXPECT_EQ(sampleTexture(repeat, {0.75, 0.5}).x, 1);
  EXPECT_DOUBLE_EQ(sampleTexture(repeat, {0.5, 0.5}).x, 0.5);
  // At u = 0 repeat blends the last texel back in, clamp stays on the first,
  // mirror reflects it.
  EXPECT_DOUBLE_EQ(sampleTexture(repeat, {0.0, 0.5}).x, 0.5);
  EXPECT_EQ(sampleTexture(clamp, {0.0, 0.5}).x, 0);
  EXPECT_EQ(sampleTexture(mirror, {0.0, 0.5}).x, 0);
  // One period on: repeat is periodic, clamp holds the edge, mirror flips.
  EXPECT_DOUBLE_EQ(sampleTexture(repeat, {1.25, 0.5}).x, 0);
  EXPECT_EQ(sampleTexture(clamp, {1.25, 0.5}).x, 1);
  EXPECT_EQ(sampleTexture(clamp, {-7.0, 0.5}).x, 0);
  EXPECT_DOUBLE_EQ(sampleTexture(mirror, {1.25, 0.5}).x, 1);
  EXPECT_DOUBLE_EQ(sampleTexture(mirror, {1.75, 0.5}).x, 0);
  EXPECT_DOUBLE_EQ(sampleTexture(mirror, {-0.25, 0.5}).x, 0);
  // Huge coordinates reduce to one period instead of overflowing an index.
  const double far = sampleTexture(repeat, {1e300, 0.5}).x;
  EXPECT_TRUE(far >= 0 && far <= 1);
  EXPECT_EQ(sampleTexture(repeat, {-3.75, 0.5}).x, 0);
}

TEST(Texture, RowsRunFromTheTop) {
  // Row 0 red, row 1 blue: v = 0.25 is red, v = 0.75 blue (glTF convention).
  const Texture t = texture(1, 2, {255, 0, 0, 0, 0, 255}, TextureWrap::ClampToEdge);
  const Vec3 top = sampleTexture(t, {0.5, 0.25}), bottom = sampleTexture(t, {0.5, 0.75});
  EXPECT_EQ(top.x, 1);
  EXPECT_EQ(top.z, 0);
  EXPECT_EQ(bottom.x, 0);
  EXPECT_EQ(bottom.z, 1);
}

TEST(Texture, ValidationNamesTheProblem) {
  Scene scene;
  scene.materials.push_back(Material{"m"});
  scene.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, 0});
  EXPECT_NO_THROW(validateTextures(scene, "s"));
  scene.materials[0].diffuseTexture = 0;
  EXPECT_THROW(validateTextures(scene, "s"), InputError);  // no texture 0
  scene.textures.push_back(texture(2, 1, {1, 2, 3, 4, 5, 6}));
  EXPECT_NO_THROW(validateTextures(scene, "s"));
  scene.textures[0].rgb.pop_back();
  EXPECT_THROW(validateTextures(scene, "s"), InputError);
  scene.textures[0] = texture(0, 1, {});
  EXPECT_THROW(validateTextures(scene, "s"), InputError);
  scene.textures[0] = texture(2, 1, {1, 2, 3, 4, 5, 6});
  scene.textures[0].wrapV = TextureWrap(7);
  EXPECT_THROW(validateTextures(scene, "s"), InputError);
  scene.textures[0].wrapV = TextureWrap::Repeat;
  scene.triangleUVs.resize(2);
  EXPECT_THROW(validateTextures(scene, "s"),
               InputError);  // not one per triangle
  scene.triangleUVs.resize(1);
  scene.triangleUVs[0][2].v = std::numeric_limits<double>::infinity();
  try {
    validateScene(scene, "scene.gltf");
    FAIL() << "infinite texture coordinate accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.gltf: triangle 0: texture coordinate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vox
