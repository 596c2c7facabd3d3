// Small helpers shared by the tests: temporary folders and random scenes.
#pragma once

#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "vox/core/scene.h"

namespace vox::testing {

// Whether the sanitizers are on (the CI's second run): the tests then run the same checks on smaller inputs.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

#ifdef VOX_SEED_DIR
// A file of the bundled test data (data/), by its path inside it.
inline std::string seed(const std::string& rel) { return std::string(VOX_SEED_DIR) + "/" + rel; }
#endif

// The whole content of a file, "" when it cannot be read.
inline std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag) {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("vox_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A closed axis-aligned box surface [a, b]^3 of 12 outward-oriented triangles.
inline Scene boxScene(double a, double b) {
  Scene scene;
  scene.materials.push_back({});
  Vec3 p[8];
  for (int c = 0; c < 8; ++c) p[c] = {(c & 1) ? b : a, (c & 2) ? b : a, (c & 4) ? b : a};
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    scene.triangles.push_back({{p[q[0]], p[q[1]], p[q[2]]}});
    scene.triangles.push_back({{p[q[0]], p[q[2]], p[q[3]]}});
  }
  return scene;
}

// Random triangles (some degenerate, some tiny) and spheres (some ellipsoids) inside [lo, lo + size]^3.
inline Scene randomScene(uint32_t seed, int triangles, int spheres, double lo = 0, double size = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto point = [&] { return Vec3{lo + size * u(rng), lo + size * u(rng), lo + size * u(rng)}; };
  Scene scene;
  scene.materials.push_back({});
  for (int i = 0; i < triangles; ++i) {
    Triangle t;
    t.v[0] = point();
    const double extent = size * (i % 3 == 0 ? 0.4 : 0.08);
    for (int k = 1; k < 3; ++k)
      t.v[k] = t.v[0] + Vec3{extent * (u(rng) - 0.5), extent * (u(rng) - 0.5), extent * (u(rng) - 0.5)};
    if (i % 17 == 5) t.v[2] = t.v[1];  // degenerate
    scene.triangles.push_back(t);
  }
  for (int i = 0; i < spheres; ++i) {
    Sphere s;
    s.center = point();
    s.radius = size * (0.02 + 0.15 * u(rng));
    if (i % 2 == 1) s.transform = translation({0.01, 0, 0}) * rotation({1, 1, 0}, 20) * scaling({1, 0.5, 1.5});
    scene.spheres.push_back(s);
  }
  return scene;
}

// The example count of a seeded property loop: `ci` in the test command, VOX_PROPERTY_RUNS for a longer run by hand.
inline int propertyRuns(int ci) {
  const char* env = std::getenv("VOX_PROPERTY_RUNS");
  return env && std::atoi(env) > 0 ? std::atoi(env) : ci;
}

// A tetrahedron of four outward-oriented triangles (a, b, c, d in any order; a flat one has no inside).
inline Scene tetrahedronScene(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  Scene s;
  s.materials.push_back({});
  const Vec3 p[4] = {a, b, c, d};
  const int faces[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {1, 3, 2, 0}, {0, 2, 3, 1}};
  for (const auto& f : faces) {
    Triangle t{{p[f[0]], p[f[1]], p[f[2]]}};
    if (dot(cross(t.v[1] - t.v[0], t.v[2] - t.v[0]), p[f[3]] - t.v[0]) > 0) std::swap(t.v[1], t.v[2]);
    s.triangles.push_back(t);
  }
  return s;
}

// A sphere of radius r about c as a closed mesh: an octahedron subdivided `levels` times, its vertices pushed onto
// the sphere; outward triangles. `bowl`: only the triangles below the plane z = c.z + cut r (an open bowl).
inline Scene sphereMesh(const Vec3& c, double r, int levels, bool bowl = false, double cut = 0) {
  std::vector<std::array<Vec3, 3>> tris;
  for (int sx = -1; sx <= 1; sx += 2)
    for (int sy = -1; sy <= 1; sy += 2)
      for (int sz = -1; sz <= 1; sz += 2) {
        std::array<Vec3, 3> t{Vec3{double(sx), 0, 0}, Vec3{0, double(sy), 0}, Vec3{0, 0, double(sz)}};
        if (sx * sy * sz < 0) std::swap(t[1], t[2]);
        tris.push_back(t);
      }
  for (int l = 0; l < levels; ++l) {
    std::vector<std::array<Vec3, 3>> next;
    for (const auto& t : tris) {
      const Vec3 m[3] = {normalize(t[0] + t[1]), normalize(t[1] + t[2]), normalize(t[2] + t[0])};
      next.push_back({t[0], m[0], m[2]});
      next.push_back({m[0], t[1], m[1]});
      next.push_back({m[2], m[1], t[2]});
      next.push_back({m[0], m[1], m[2]});
    }
    tris = std::move(next);
  }
  Scene s;
  s.materials.push_back({});
  for (const auto& t : tris) {
    if (bowl && (t[0].z + t[1].z + t[2].z) / 3 > cut) continue;
    s.triangles.push_back({{c + t[0] * r, c + t[1] * r, c + t[2] * r}});
  }
  return s;
}

}  // namespace vox::testing
