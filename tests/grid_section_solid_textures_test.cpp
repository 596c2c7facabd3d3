// The SolidTextures section of grid files (io/grid_section_solid_textures.cpp): exact round trip, an image
// identical before and after, every truncation and bit flip refused, and hostile bodies with a valid checksum
// (bad kinds, indices, order, octaves, cycles, deep nesting) refused with an error naming the file.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "grid_file_util.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/grid_file.h"
#include "vox/trace/accel.h"
#include "vox/trace/render.h"
#include "vox/voxelize/voxelize.h"

#include "../fuzz/fuzz_entry.h"

namespace vox {
namespace {

using testing::resealed;
using testing::smallGrid;

constexpr size_t kTextureBytes = 1 + 16 * 8 + 4 + 4 + 4 + 8 + 8;

Scene solidTexturedScene() {
  Scene s = testing::randomScene(4, 5, 2);
  Material red, blue;
  red.diffuse = {1, 0, 0};
  blue.diffuse = {0, 0, 1};
  blue.reflective = {0.5, 0.5, 0.5};
  s.materials = {red, blue, {}, {}};
  SolidTexture checker;
  checker.transform = scaling({4, 4, 4});
  checker.materials[0] = 0, checker.materials[1] = 1;
  SolidTexture wood;
  wood.kind = SolidKind::Wood;
  wood.transform = rotation({1, 0, 0}, 90) * translation({0.1, 0.2, 0.3});
  wood.materials[0] = 2, wood.materials[1] = 0;  // nests the checkerboard
  wood.octaves = 3, wood.frequency = 6.5, wood.amplitude = 1.25;
  s.solidTextures = {checker, wood};
  s.materials[2].solidTexture = 0;
  s.materials[3].solidTexture = 1;
  for (size_t i = 0; i < s.triangles.size(); ++i) s.triangles[i].material = uint32_t(i % 4);
  for (auto& sp : s.spheres) sp.material = 3;
  s.planes.push_back(Plane{{0, 1, 0}, -0.1, 2});
  return s;
}

// Offset of the section body: it is written last, and its size follows from its counts.
size_t bodyOffset(const Scene& s) {
  size_t textured = 0;
  for (const Material& m : s.materials) textured += m.solidTexture != kNoSolidTexture;
  return 8 + s.solidTextures.size() * kTextureBytes + 8 + textured * 8;
}

TEST(GridSectionSolidTextures, RoundTripIsExactAndRendersTheSame) {
  const Scene s = solidTexturedScene();
  const Grid g = smallGrid(s, 3);
  const GridFile f = decodeGridFile(encodeGridFile(s, g), "t.vgrid");
  ASSERT_EQ(f.scene.solidTextures.size(), s.solidTextures.size());
  for (size_t i = 0; i < s.solidTextures.size(); ++i) {
    const SolidTexture &a = s.solidTextures[i], &b = f.scene.solidTextures[i];
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(std::memcmp(&a.transform, &b.transform, sizeof(Mat4)), 0);
    EXPECT_EQ(a.materials[0], b.materials[0]);
    EXPECT_EQ(a.materials[1], b.materials[1]);
    EXPECT_EQ(a.octaves, b.octaves);
    EXPECT_EQ(a.frequency, b.frequency);
    EXPECT_EQ(a.amplitude, b.amplitude);
  }
  for (size_t i = 0; i < s.materials.size(); ++i)
    EXPECT_EQ(f.scene.materials[i].solidTexture, s.materials[i].solidTexture);
  RenderOptions ro;
  ro.width = ro.height = 24;
  ro.bounces = 2;
  ro.camera = defaultCamera(*sceneBounds(s));
  const Image before = traceImage(s, buildAccel(s, g, AccelKind::Grid), ro);
  const Image after = traceImage(f.scene, buildAccel(f.scene, f.grid, AccelKind::Grid), ro);
  EXPECT_EQ(before.pixels, after.pixels);
  // Without textures no section is written.
  Scene plain = s;
  plain.solidTextures.clear();
  for (Material& m : plain.materials) m.solidTexture = kNoSolidTexture;
  EXPECT_EQ(encodeGridFile(plain, g).size() + 12 + bodyOffset(s), encodeGridFile(s, g).size());
}

TEST(GridSectionSolidTextures, EveryTruncationAndBitFlipIsRefused) {
  const Scene s = solidTexturedScene();
  const std::string bytes = encodeGridFile(s, smallGrid(s, 3));
  // Only the section's own bytes and its header: the rest of the file is the general test's.
  for (size_t n = bytes.size() - bodyOffset(s) - 12; n < bytes.size(); ++n)
    EXPECT_THROW(decodeGridFile(bytes.substr(0, n), "cut.vgrid"), InputError) << n;
  for (size_t bit = (bytes.size() - bodyOffset(s) - 12) * 8; bit < bytes.size() * 8; ++bit) {
    std::string flipped = bytes;
    flipped[bit / 8] = char(flipped[bit / 8] ^ (1 << (bit % 8)));
    EXPECT_THROW(decodeGridFile(flipped, "flip.vgrid"), InputError) << "bit " << bit;
  }
}

TEST(GridSectionSolidTextures, HostileBodiesWithAValidChecksumAreRefused) {
  const Scene s = solidTexturedScene();
  const std::string bytes = encodeGridFile(s, smallGrid(s, 3));
  const size_t body = bytes.size() - bodyOffset(s);
  const size_t tex1 = body + 8 + kTextureBytes;  // the Wood texture
  const size_t pairs = body + 8 + 2 * kTextureBytes + 8;
  const auto refused = [&](std::string m, const char* what) {
    try {
      decodeGridFile(resealed(std::move(m)), "hostile.vgrid");
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("hostile.vgrid", 0), 0u) << what << ": " << e.what();
      return;
    }
    ADD_FAILURE() << what << " accepted";
  };
  const auto put32 = [](std::string m, size_t at, uint32_t v) {
    std::memcpy(&m[at], &v, 4);
    return m;
  };
  const auto put64 = [](std::string m, size_t at, uint64_t v) {
    std::memcpy(&m[at], &v, 8);
    return m;
  };
  refused(put64(bytes, body, 0), "no textures");
  refused(put64(bytes, body, uint64_t(1) << 60), "absurd texture count");
  std::string kind = bytes;
  kind[tex1] = 9;
  refused(kind, "unknown kind");
  kind[tex1] = 0;
  refused(kind, "kind 0");
  const double nan = std::nan("");
  std::string transform = bytes;
  std::memcpy(&transform[tex1 + 1 + 8 * 5], &nan, 8);
  refused(transform, "NaN in the transform");
  refused(put32(bytes, tex1 + 1 + 128, 4), "material out of range");
  refused(put32(bytes, tex1 + 1 + 128 + 8, kMaxOctaves + 1), "too many octaves");
  std::string freq = bytes;
  std::memcpy(&freq[tex1 + 1 + 128 + 12], &nan, 8);
  refused(freq, "NaN frequency");
  refused(put32(bytes, tex1 + 1 + 128, 3), "a cycle: the wood blends itself");
  refused(put32(bytes, pairs, 3), "materials out of order");
  refused(put32(bytes, pairs + 4, 2), "texture out of range");
  refused(put32(bytes, pairs + 8, 9), "textured material out of range");
  refused(put64(bytes, body + 8 + 2 * kTextureBytes, 3), "more pairs than the body holds");
  // A chain deeper than kMaxSolidNesting, written by a buggy or hostile writer.
  Scene deep;
  deep.materials.push_back({});
  for (uint32_t i = 0; i <= kMaxSolidNesting; ++i) {
    SolidTexture t;
    t.materials[0] = t.materials[1] = uint32_t(deep.materials.size() - 1);
    deep.solidTextures.push_back(t);
    Material m;
    m.solidTexture = i;
    deep.materials.push_back(m);
  }
  deep.triangles.push_back(Triangle{{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, 0});
  refused(encodeGridFile(deep, smallGrid(deep, 3)), "nesting too deep");
}

TEST(GridSectionSolidTextures, MutationsWithValidChecksumDecodeOrThrow) {
  const Scene s = solidTexturedScene();
  const std::string bytes = encodeGridFile(s, smallGrid(s, 3));
  const size_t body = bytes.size() - bodyOffset(s);
  std::mt19937 rng(29);
  int accepted = 0;
  for (int n = 0; n < 3000; ++n) {
    std::string m = bytes;
    for (int e = 0; e < 1 + int(rng() % 3); ++e) m[body + rng() % (m.size() - body)] = char(rng());
    try {
      const GridFile file = decodeGridFile(resealed(m), "fuzz.vgrid");
      if (++accepted <= 100) fuzz::exerciseDecodedGrid(file);
    } catch (const InputError& e) {
      ASSERT_EQ(std::string(e.what()).rfind("fuzz.vgrid", 0), 0u) << e.what();
    }
  }
  RecordProperty("accepted", accepted);
}

}  // namespace
}  // namespace vox
