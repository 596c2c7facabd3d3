// A float image: what the renderer makes (trace/render.h) and the image writer writes (io/image_io.h), so it sits
// below both.
#pragma once

#include <cstdint>
#include <vector>

namespace vox {

// Rows from the top, pixels interleaved: pixels[(y * width + x) * channels + c].
struct Image {
  uint32_t width = 0, height = 0, channels = 3;
  std::vector<float> pixels;

  float* at(uint32_t x, uint32_t y) { return pixels.data() + (uint64_t(y) * width + x) * channels; }
  const float* at(uint32_t x, uint32_t y) const { return pixels.data() + (uint64_t(y) * width + x) * channels; }
};

}  // namespace vox
