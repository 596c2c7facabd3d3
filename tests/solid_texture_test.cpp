// Perlin noise and the course's solid textures (solid_texture.cpp, perlin_noise.cpp, material_at.cpp) against
// values computed here from their definitions, independently of the library's code.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "vox/core/error.h"
#include "vox/core/material_at.h"
#include "vox/core/solid_texture.h"

namespace vox {
namespace {

// Perlin's improved noise written out from the paper's definition: the gradient of each lattice corner is one of
// the twelve cube edge vectors (hash mod 16, the four extra ones repeating (1,1,0), (-1,1,0), (0,-1,1), (0,-1,-1)),
// the corner's contribution is gradient . offset, blended with the quintic 6t^5 - 15t^4 + 10t^3. The hash is the
// reference permutation applied as P[P[P[X] + Y] + Z].
const int kP[256] = {151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,
                     69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,
                     94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136,
                     171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122,
                     60,  211, 133, 230, 220, 105, 92,  41,  55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161,
                     1,   216, 80,  73,  209, 76,  132, 187, 208, 89,  18,  169, 200, 196, 135, 130, 116, 188, 159, 86,
                     164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250, 124, 123, 5,   202, 38,  147, 118, 126,
                     255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189, 28,  42,  223, 183, 170, 213,
                     119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,   129, 22,  39,  253,
                     19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,  242, 193,
                     238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
                     181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,
                     222, 114, 67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};
const double kGrad[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                             {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                             {1, 1, 0},  {0, -1, 1},  {-1, 1, 0}, {0, -1, -1}};

int hashCorner(int x, int y, int z) {
  const auto p = [](int i) { return kP[((i % 256) + 256) % 256]; };
  return p(p(p(x) + y) + z);
}

double referenceNoise(double x, double y, double z) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const int X = int(fx), Y = int(fy), Z = int(fz);
  const double dx = x - fx, dy = y - fy, dz = z - fz;
  const auto quintic = [](double t) { return 6 * std::pow(t, 5) - 15 * std::pow(t, 4) + 10 * std::pow(t, 3); };
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1, j = (c >> 1) & 1, k = (c >> 2) & 1;
    const double* g = kGrad[hashCorner((X + i) & 255, (Y + j) & 255, (Z + k) & 255) & 15];
    const double dot = g[0] * (dx - i) + g[1] * (dy - j) + g[2] * (dz - k);
    const double wx = i ? quintic(dx) : 1 - quintic(dx);
    const double wy = j ? quintic(dy) : 1 - quintic(dy);
    const double wz = k ? quintic(dz) : 1 - quintic(dz);
    sum += wx * wy * wz * dot;
  }
  return sum;
}

TEST(PerlinNoise, MatchesTheDefinitionAndTheReferenceValue) {
  // The value printed by Perlin's Java reference for noise(3.14, 42, 7).
  EXPECT_NEAR(perlinNoise(3.14, 42, 7), 0.13691995878400012, 1e-15);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-300, 300);
  double lo = 0, hi = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    const double n = perlinNoise(x, y, z);
    ASSERT_NEAR(n, referenceNoise(x, y, z), 1e-12) << x << " " << y << " " << z;
    lo = std::min(lo, n), hi = std::max(hi, n);
  }
  EXPECT_GE(lo, -1.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_LT(lo, -0.4);  // really varies
  EXPECT_GT(hi, 0.4);
  // Zero at every lattice point; continuous across cell faces.
  for (int x = -3; x <= 3; ++x) EXPECT_EQ(perlinNoise(x, 2 * x, -x + 7), 0.0);
  EXPECT_NEAR(perlinNoise(1 - 1e-12, 0.3, 0.7), perlinNoise(1 + 1e-12, 0.3, 0.7), 1e-10);
  // Huge and non-finite coordinates stay defined.
  EXPECT_TRUE(std::isfinite(perlinNoise(1e300, -1e300, 3.5)));
  EXPECT_EQ(perlinNoise(NAN, 0, 0), 0.0);
}

TEST(SolidTextures, WeightsFollowTheirDefinitions) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-4, 4);
  SolidTexture t;
  t.transform = scaling({2, 2, 2});  // texture space = 2 * world
  for (int i = 0; i < 2000; ++i) {
    const Vec3 w{u(rng), u(rng), u(rng)};
    const Vec3 p = w * 2;
    double n = 0;
    for (int o = 0; o < 5; ++o) n += referenceNoise(p.x * (1 << o), p.y * (1 << o), p.z * (1 << o)) / (1 << o);
    t.kind = SolidKind::Checkerboard;
    const long long parity = (long long)std::floor(p.x) + (long long)std::floor(p.y) + (long long)std::floor(p.z);
    EXPECT_EQ(solidTextureWeight(t, w), parity % 2 == 0 ? 1.0 : 0.0);
    t.kind = SolidKind::Noise;
    t.octaves = 5;
    EXPECT_NEAR(octaveNoise(p, 5), n, 1e-12);
    EXPECT_NEAR(solidTextureWeight(t, w), std::min(1.0, std::max(0.0, n + 0.5)), 1e-12);
    t.kind = SolidKind::Marble;
    t.frequency = 3, t.amplitude = 2;
    EXPECT_NEAR(solidTextureWeight(t, w), (1 + std::sin(3 * p.x + 2 * n)) / 2, 1e-12);
    t.kind = SolidKind::Wood;
    EXPECT_NEAR(solidTextureWeight(t, w), (1 + std::sin(3 * std::hypot(p.x, p.z) + 2 * n)) / 2, 1e-12);
  }
  // Checkerboard squares switch exactly at integer texture coordinates, negative ones included.
  t.kind = SolidKind::Checkerboard;
  t.transform = Mat4::identity();
  EXPECT_EQ(solidTextureWeight(t, {0.5, 0.5, 0.5}), 1.0);
  EXPECT_EQ(solidTextureWeight(t, {-0.5, 0.5, 0.5}), 0.0);
  EXPECT_EQ(solidTextureWeight(t, {-1e-300, 0.5, 0.5}), 0.0);
  EXPECT_EQ(solidTextureWeight(t, {0.0, 0.5, 0.5}), 1.0);
  EXPECT_EQ(solidTextureWeight(t, {-1.5, 0.5, 0.5}), 1.0);   // -2 + 0 + 0: even
  EXPECT_EQ(solidTextureWeight(t, {-1.5, -0.5, 0.5}), 0.0);  // -2 - 1 + 0: odd
}

Scene nestedScene() {
  Scene s;
  Material red, blue, green;
  red.diffuse = {1, 0, 0};
  blue.diffuse = {0, 0, 1};
  green.diffuse = {0, 1, 0};
  green.exponent = 9;
  s.materials = {red, blue, green, {}, {}};
  SolidTexture checker;  // material 3: red / blue checks
  checker.materials[0] = 0, checker.materials[1] = 1;
  SolidTexture marble;  // material 4: marble of the checkerboard and green
  marble.kind = SolidKind::Marble;
  marble.materials[0] = 3, marble.materials[1] = 2;
  marble.octaves = 2, marble.frequency = 1.5, marble.amplitude = 0.7;
  s.solidTextures = {checker, marble};
  s.materials[3].solidTexture = 0;
  s.materials[4].solidTexture = 1;
  return s;
}

TEST(SolidTextures, NestedMaterialsBlendTheirPhongParameters) {
  const Scene s = nestedScene();
  validateSolidTextures(s, "nested");
  const Vec3 p{0.3, 1.2, -0.4};  // floor sum 0 + 1 - 1 = 0: even, red
  const double v =
      (1 +
       std::sin(1.5 * p.x + 0.7 * (referenceNoise(p.x, p.y, p.z) + referenceNoise(2 * p.x, 2 * p.y, 2 * p.z) / 2))) /
      2;
  const Material m = materialAt(s, 4, p);
  EXPECT_NEAR(m.diffuse.x, v, 1e-12);
  EXPECT_NEAR(m.diffuse.y, 1 - v, 1e-12);
  EXPECT_NEAR(m.diffuse.z, 0, 1e-12);
  EXPECT_NEAR(m.exponent, v * 1 + (1 - v) * 9, 1e-12);
  EXPECT_EQ(m.solidTexture, kNoSolidTexture);
  EXPECT_EQ(materialAt(s, 3, {1.5, 0.5, 0.5}).diffuse.z, 1.0);  // odd square: blue
}

TEST(SolidTextures, ValidationRefusesBadReferencesCyclesAndDeepNesting) {
  const auto refused = [](const Scene& s) {
    try {
      validateSolidTextures(s, "bad.vgrid");
    } catch (const InputError& e) {
      return std::string(e.what()).find("bad.vgrid") == 0;
    }
    return false;
  };
  Scene s = nestedScene();
  s.solidTextures[1].materials[1] = 7;  // out of range
  EXPECT_TRUE(refused(s));
  s = nestedScene();
  s.materials[2].solidTexture = 5;  // no such texture
  EXPECT_TRUE(refused(s));
  s = nestedScene();
  s.solidTextures[0].materials[0] = 4;  // 4 -> 3 -> 4: a cycle
  EXPECT_TRUE(refused(s));
  s = nestedScene();
  s.solidTextures[1].octaves = kMaxOctaves + 1;
  EXPECT_TRUE(refused(s));
  s = nestedScene();
  s.solidTextures[1].transform.m[0][0] = NAN;
  EXPECT_TRUE(refused(s));
  // A chain of kMaxSolidNesting textures is accepted, one more is refused.
  for (uint32_t depth : {kMaxSolidNesting, kMaxSolidNesting + 1}) {
    Scene chain;
    chain.materials.push_back({});
    for (uint32_t i = 0; i < depth; ++i) {
      SolidTexture t;
      t.materials[0] = t.materials[1] = uint32_t(chain.materials.size() - 1);
      chain.solidTextures.push_back(t);
      Material m;
      m.solidTexture = i;
      chain.materials.push_back(m);
    }
    EXPECT_EQ(refused(chain), depth > kMaxSolidNesting) << depth;
  }
}

}  // namespace
}  // namespace vox
