#include "vox/core/colormap.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace vox {

namespace {
// matplotlib's viridis (van der Walt and Smith, 2015) sampled at t = 0, 1/8, ..., 1, as 8-bit sRGB.
constexpr std::array<std::array<double, 3>, 9> kViridis{{{68, 1, 84},
                                                         {72, 40, 120},
                                                         {62, 73, 137},
                                                         {49, 104, 142},
                                                         {38, 130, 142},
                                                         {31, 158, 137},
                                                         {53, 183, 121},
                                                         {110, 206, 88},
                                                         {253, 231, 37}}};
}  // namespace

Vec3 viridis(double t) {
  if (!(t > 0)) t = 0;  // also catches NaN
  if (t > 1) t = 1;
  const double x = t * double(kViridis.size() - 1);
  const size_t i = std::min(size_t(x), kViridis.size() - 2);
  const double f = x - double(i);
  const auto& a = kViridis[i];
  const auto& b = kViridis[i + 1];
  return Vec3{a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f} / 255.0;
}

Vec3 countColor(uint32_t count, uint32_t maxCount) {
  if (count <= 1 || maxCount <= 1) return viridis(0);
  if (count >= maxCount) return viridis(1);
  return viridis(std::log(double(count)) / std::log(double(maxCount)));
}

Vec3 heatColor(double value, double maxValue) {
  double x = maxValue > 0 ? value / maxValue : 0;
  x = std::clamp(x, 0.0, 1.0);
  // Piecewise-linear ramp: black-blue, blue, red, yellow, white.
  static const Vec3 stops[] = {{0, 0, 0.15}, {0.1, 0.2, 0.9}, {0.9, 0.1, 0.1}, {1, 0.85, 0}, {1, 1, 1}};
  const double f = x * 4;
  const int i = std::min(3, int(f));
  const double w = f - i;
  return stops[i] * (1 - w) + stops[i + 1] * w;
}

}  // namespace vox
