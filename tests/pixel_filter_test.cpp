// Reconstruction filters (trace/pixel_filter.h): weights in closed form, supports, and filtering of kept samples
// against sums computed here.
#include <gtest/gtest.h>

#include <cmath>

#include "trace/pixel_filter.h"

namespace vox {
namespace {

TEST(PixelFilter, WeightsAndSupports) {
  EXPECT_EQ(filterWeight(FilterKind::Box, 0.5, 0.49, -0.49), 1.0);
  EXPECT_EQ(filterWeight(FilterKind::Box, 0.5, 0.5, 0), 0.0);          // open square
  EXPECT_DOUBLE_EQ(filterWeight(FilterKind::Tent, 2, 0.6, 0.8), 0.5);  // d = 1
  EXPECT_EQ(filterWeight(FilterKind::Tent, 2, 2, 0), 0.0);
  EXPECT_DOUBLE_EQ(filterWeight(FilterKind::Gaussian, 0.4, 0.4, 0), std::exp(-0.5));
  EXPECT_DOUBLE_EQ(filterWeight(FilterKind::Gaussian, 0.4, 0.79, 0), std::exp(-0.79 * 0.79 / 0.32));
  EXPECT_EQ(filterWeight(FilterKind::Gaussian, 0.4, 0.8, 0), 0.0);  // support 2 sigma
  // Samples lie within half a pixel of their pixel's centre.
  EXPECT_EQ(filterSupport(FilterKind::Box, 0.5), 0u);
  EXPECT_EQ(filterSupport(FilterKind::Gaussian, 0.4), 1u);
  EXPECT_EQ(filterSupport(FilterKind::Tent, 1.5), 1u);
  EXPECT_EQ(filterSupport(FilterKind::Tent, 1.6), 2u);
}

TEST(PixelFilter, FilteredImageIsTheWeightedMeanOfNearbySamples) {
  SampleStore store = makeSampleStore(5, 4, 2, 3);
  // Sample s of pixel (x, y) at offset (0.25 + 0.5 s, 0.5), value x + 10 y + 100 s in every channel.
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 5; ++x)
      for (uint32_t s = 0; s < 2; ++s) {
        const float v[3] = {float(x + 10 * y + 100 * s), float(x + 10 * y + 100 * s), 1.0f};
        store.put(x, y, s, 0.25 + 0.5 * s, 0.5, v);
      }
  for (FilterKind kind : {FilterKind::Box, FilterKind::Tent, FilterKind::Gaussian})
    for (double r : {0.3, 0.7, 1.2}) {
      const Image img = filterSamples(store, kind, r);
      for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 5; ++x) {
          double sum = 0, total = 0;
          for (int ny = 0; ny < 4; ++ny)
            for (int nx = 0; nx < 5; ++nx)
              for (int s = 0; s < 2; ++s) {
                const double w = filterWeight(kind, r, nx - int(x) + 0.25 + 0.5 * s - 0.5, ny - int(y));
                sum += w * (nx + 10 * ny + 100 * s);
                total += w;
              }
          ASSERT_GT(total, 0);
          EXPECT_NEAR(img.at(x, y)[0], sum / total, 1e-4) << int(kind) << " " << r << " " << x << " " << y;
          EXPECT_FLOAT_EQ(img.at(x, y)[2], 1.0f);  // a constant stays constant
        }
    }
}

}  // namespace
}  // namespace vox
