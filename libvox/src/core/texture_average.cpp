// Area-weighted texture averages over a cell (texture_average.h).
#include "vox/core/texture_average.h"

#include <algorithm>
#include <cmath>

#include "core/clip_triangle.h"

namespace vox {

namespace {

constexpr int kMaxSubdivision = 32;  // at most 1024 samples per piece of a clipped triangle

TexCoord uvAt(const std::array<TexCoord, 3>& uv, const Vec3& b) {
  return {b.x * uv[0].u + b.y * uv[1].u + b.z * uv[2].u, b.x * uv[0].v + b.y * uv[1].v + b.z * uv[2].v};
}

// A fixed pseudo-random point of the unit right triangle {a, b >= 0, a + b <=
// 1} for stratum `key` (splitmix64).
std::array<double, 2> jitter(uint64_t key) {
  auto next = [&key] {
    uint64_t z = (key += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  double a = next(), b = next();
  if (a + b > 1) a = 1 - a, b = 1 - b;
  return {a, b};
}

// Mean texture colour over the triangle of texture coordinates a, b, c: split
// into n x n equal sub-triangles (the n * n upward and downward ones of the
// regular subdivision), one sample each. n grows with the texels covered, so
// each sample stands for about one texel; at the cap a sample stands for more,
// and it is placed at a fixed pseudo-random point of its sub-triangle
// (stratified sampling) rather than at the centroid, so that a regular texture
// pattern cannot alias with the regular sample pattern: the error becomes small
// noise instead of bias.
Vec3 meanOverPiece(const Texture& texture, TexCoord a, TexCoord b, TexCoord c) {
  const double texels =
      0.5 * std::fabs((b.u - a.u) * (c.v - a.v) - (c.u - a.u) * (b.v - a.v)) * texture.width * texture.height;
  const int n =
      std::clamp(int(std::ceil(std::sqrt(std::isfinite(texels) ? std::min(texels, 1e6) : 1.0))), 1, kMaxSubdivision);
  const bool stratified = n == kMaxSubdivision && texels > double(n) * n;
  auto at = [&](double s, double t) {  // s, t: weights of b and c
    return TexCoord{a.u + s * (b.u - a.u) + t * (c.u - a.u), a.v + s * (b.v - a.v) + t * (c.v - a.v)};
  };
  Vec3 sum;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      for (int down = 0; down < 2; ++down) {
        if (down && i + j + 1 >= n) continue;
        std::array<double, 2> o{1 / 3.0, 1 / 3.0};
        if (stratified) o = jitter(uint64_t(i) << 32 | uint64_t(j) << 1 | uint64_t(down));
        const double s = down ? (i + 1 - o[0]) / n : (i + o[0]) / n;
        const double t = down ? (j + 1 - o[1]) / n : (j + o[1]) / n;
        sum = sum + sampleTexture(texture, at(s, t));
      }
    }
  return sum / double(n * n);
}

}  // namespace

void addTextureOverBox(const Texture& texture, const std::array<Vec3, 3>& t, const std::array<TexCoord, 3>& uv,
                       const Box& box, TextureSum& sum) {
  const ClipPolygon poly = clipTriangleToBox(t, box);
  double covered = 0;
  for (size_t k = 1; k + 1 < poly.size; ++k) {
    const ClipVertex &a = poly.v[0], &b = poly.v[k], &c = poly.v[k + 1];
    const double area = 0.5 * length(cross(b.p - a.p, c.p - a.p));
    if (!(area > 0) || !std::isfinite(area)) continue;
    sum.area = sum.area + meanOverPiece(texture, uvAt(uv, a.bary), uvAt(uv, b.bary), uvAt(uv, c.bary)) * area;
    sum.areaWeight += area;
    covered += area;
  }
  if (covered > 0) return;
  // A contact without area: the texture at the triangle's point nearest the
  // cell's centre.
  const Vec3 bary = nearestBarycentric(t, (box.lo + box.hi) * 0.5);
  sum.touch = sum.touch + sampleTexture(texture, uvAt(uv, bary));
  sum.touchCount += 1;
}

}  // namespace vox
