// Reconstruction filters (render.h FilterKind): weights of a sample at offset (dx, dy) pixels from a pixel centre,
// and the support in whole pixels around the pixel that can hold samples of non-zero weight.
#pragma once

#include <cmath>
#include <cstdint>

#include "vox/trace/render.h"

namespace vox {

inline double filterWeight(FilterKind kind, double radius, double dx, double dy) {
  switch (kind) {
    case FilterKind::Box:
      return std::fabs(dx) < radius && std::fabs(dy) < radius ? 1.0 : 0.0;
    case FilterKind::Tent: {
      const double d = std::sqrt(dx * dx + dy * dy);
      return d < radius ? 1 - d / radius : 0.0;
    }
    case FilterKind::Gaussian: {
      const double d2 = dx * dx + dy * dy;
      return d2 < 4 * radius * radius ? std::exp(-d2 / (2 * radius * radius)) : 0.0;
    }
    case FilterKind::None:
      break;
  }
  return 0;
}

// Neighbouring pixels (on each side) whose samples can fall inside the filter: samples lie within half a pixel of
// their own pixel's centre, so a support of reach r (r, or 2r for the Gaussian) needs ceil(r - 0.5) pixels.
inline uint32_t filterSupport(FilterKind kind, double radius) {
  const double reach = kind == FilterKind::Gaussian ? 2 * radius : radius;
  return uint32_t(std::max(0.0, std::ceil(reach - 0.5)));
}

}  // namespace vox

#include <vector>

namespace vox {

// Every sample of an image kept for filtering: its position inside its pixel and its value.
struct SampleStore {
  uint32_t width = 0, height = 0, samples = 0, channels = 0;
  std::vector<float> offset;  // (dx, dy) in [0, 1) from the pixel's corner, per sample
  std::vector<float> value;   // `channels` values per sample

  bool active() const { return samples != 0; }
  void put(uint32_t x, uint32_t y, uint32_t s, double dx, double dy, const float* v) {
    const uint64_t i = (uint64_t(y) * width + x) * samples + s;
    offset[2 * i] = float(dx), offset[2 * i + 1] = float(dy);
    for (uint32_t c = 0; c < channels; ++c) value[i * channels + c] = v[c];
  }
};

// Allocates the store after checking its size against the memory budget (LimitError).
SampleStore makeSampleStore(uint32_t width, uint32_t height, uint32_t samples, uint32_t channels);
// The filtered image: each pixel the weighted mean of the samples within the filter around its centre (0 where no
// sample has weight, which a radius of at least half a pixel never leaves).
Image filterSamples(const SampleStore& store, FilterKind kind, double radius);

}  // namespace vox
