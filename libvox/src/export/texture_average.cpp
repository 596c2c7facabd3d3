// Area-weighted texture averages over a cell (texture_average.h).
#include "export/texture_average.h"

#include <algorithm>
#include <cmath>

#include "export/clip_triangle.h"

namespace vox {

namespace {

constexpr int kMaxSubdivision = 16;  // at most 256 samples per piece of a clipped triangle

TexCoord uvAt(const std::array<TexCoord, 3>& uv, const Vec3& b) {
  return {b.x * uv[0].u + b.y * uv[1].u + b.z * uv[2].u, b.x * uv[0].v + b.y * uv[1].v + b.z * uv[2].v};
}

// Mean texture colour over the triangle of texture coordinates a, b, c: n x n equal sub-triangles (n * n upward
// and downward ones of the regular subdivision), each sampled at its centroid.
Vec3 meanOverPiece(const Texture& texture, TexCoord a, TexCoord b, TexCoord c) {
  const double texels = 0.5 * std::fabs((b.u - a.u) * (c.v - a.v) - (c.u - a.u) * (b.v - a.v)) * texture.width *
                        texture.height;
  const int n = std::clamp(int(std::ceil(std::sqrt(std::isfinite(texels) ? std::min(texels, 1e6) : 1.0))), 1,
                           kMaxSubdivision);
  auto at = [&](double s, double t) {  // s, t: weights of b and c
    return TexCoord{a.u + s * (b.u - a.u) + t * (c.u - a.u), a.v + s * (b.v - a.v) + t * (c.v - a.v)};
  };
  Vec3 sum;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      sum = sum + sampleTexture(texture, at((3 * i + 1) / (3.0 * n), (3 * j + 1) / (3.0 * n)));
      if (i + j + 1 < n) sum = sum + sampleTexture(texture, at((3 * i + 2) / (3.0 * n), (3 * j + 2) / (3.0 * n)));
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
  // A contact without area: the texture at the triangle's point nearest the cell's centre.
  const Vec3 bary = nearestBarycentric(t, (box.lo + box.hi) * 0.5);
  sum.touch = sum.touch + sampleTexture(texture, uvAt(uv, bary));
  sum.touchCount += 1;
}

}  // namespace vox
