#include "trace/pixel_filter.h"

#include <tbb/parallel_for.h>

#include "vox/core/error.h"
#include "vox/core/memory_budget.h"

namespace vox {

FilterKind parseFilter(const std::string& name) {
  if (name == "box") return FilterKind::Box;
  if (name == "tent") return FilterKind::Tent;
  if (name == "gaussian") return FilterKind::Gaussian;
  fail<UsageError>("unknown filter '", name, "' (expected box, tent or gaussian)");
}

SampleStore makeSampleStore(uint32_t width, uint32_t height, uint32_t samples, uint32_t channels) {
  const double count = double(width) * height * samples;
  checkMemory(count * (2 + channels) * sizeof(float), "filter", "the samples of a filtered image");
  SampleStore s;
  s.width = width, s.height = height, s.samples = samples, s.channels = channels;
  s.offset.assign(uint64_t(count) * 2, 0.0f);
  s.value.assign(uint64_t(count) * channels, 0.0f);
  return s;
}

Image filterSamples(const SampleStore& store, FilterKind kind, double radius) {
  Image image;
  image.width = store.width, image.height = store.height, image.channels = store.channels;
  image.pixels.assign(uint64_t(store.width) * store.height * store.channels, 0.0f);
  const int64_t reach = filterSupport(kind, radius);
  tbb::parallel_for(uint32_t(0), store.height, [&](uint32_t y) {
    std::vector<double> sum(store.channels);
    for (uint32_t x = 0; x < store.width; ++x) {
      std::fill(sum.begin(), sum.end(), 0.0);
      double total = 0;
      for (int64_t ny = std::max<int64_t>(0, y - reach); ny <= std::min<int64_t>(store.height - 1, y + reach); ++ny)
        for (int64_t nx = std::max<int64_t>(0, x - reach); nx <= std::min<int64_t>(store.width - 1, x + reach); ++nx)
          for (uint32_t s = 0; s < store.samples; ++s) {
            const uint64_t i = (uint64_t(ny) * store.width + nx) * store.samples + s;
            // Offset of the sample from this pixel's centre, in pixels.
            const double dx = double(nx - x) + store.offset[2 * i] - 0.5;
            const double dy = double(ny - y) + store.offset[2 * i + 1] - 0.5;
            const double w = filterWeight(kind, radius, dx, dy);
            if (w == 0) continue;
            total += w;
            for (uint32_t c = 0; c < store.channels; ++c) sum[c] += w * store.value[i * store.channels + c];
          }
      float* out = image.at(x, y);
      for (uint32_t c = 0; c < store.channels; ++c) out[c] = total > 0 ? float(sum[c] / total) : 0.0f;
    }
  });
  return image;
}

}  // namespace vox
