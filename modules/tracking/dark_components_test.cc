#include "tracking/dark_components.h"

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tracking/tracking_test_util.h"

namespace selfcal::tracking::internal {
namespace {

// The definition, pixel by pixel: dark when I <= threshold (threshold >= 0), else by the box sum in 64
// bits; then a breadth-first fill from each new dark pixel in raster order.
std::vector<Component> ReferenceComponents(const vpImage<unsigned char>& image, int window, int offset,
                                           int threshold = -1) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight()), half = window / 2;
  std::vector<std::uint8_t> dark(static_cast<size_t>(w * h), 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      std::int64_t sum = 0, n = 0;
      for (int y = std::max(0, v - half); y <= std::min(h - 1, v + half); ++y) {
        for (int x = std::max(0, u - half); x <= std::min(w - 1, u + half); ++x) {
          sum += image[y][x];
          ++n;
        }
      }
      const bool is_dark = threshold >= 0 ? image[v][u] <= threshold : n * (image[v][u] + offset) <= sum;
      dark[static_cast<size_t>(v * w + u)] = is_dark ? 1 : 0;
    }
  }
  std::vector<Component> components;
  std::vector<std::pair<int, int>> queue;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (dark[static_cast<size_t>(v * w + u)] != 1) continue;
      std::vector<std::pair<int, int>> pixels;
      queue.assign(1, {u, v});
      dark[static_cast<size_t>(v * w + u)] = 2;
      for (size_t k = 0; k < queue.size(); ++k) {
        const auto [x, y] = queue[k];
        pixels.push_back(queue[k]);
        for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny) {
          for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx) {
            if (dark[static_cast<size_t>(ny * w + nx)] != 1) continue;
            dark[static_cast<size_t>(ny * w + nx)] = 2;
            queue.emplace_back(nx, ny);
          }
        }
      }
      std::sort(pixels.begin(), pixels.end(), [](const auto& a, const auto& b) {
        return a.second != b.second ? a.second < b.second : a.first < b.first;
      });
      Component c;
      for (const auto& [x, y] : pixels) {
        ++c.count;
        c.bbox.u_min = std::min(c.bbox.u_min, x);
        c.bbox.v_min = std::min(c.bbox.v_min, y);
        c.bbox.u_max = std::max(c.bbox.u_max, x);
        c.bbox.v_max = std::max(c.bbox.v_max, y);
        if (image[y][x] < c.darkest) {
          c.darkest = image[y][x];
          c.darkest_u = x;
          c.darkest_v = y;
        }
      }
      components.push_back(c);
    }
  }
  return components;
}

void ExpectSame(const std::vector<Component>& expected, const std::vector<Component>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(expected[i].count, actual[i].count);
    EXPECT_TRUE(expected[i].bbox == actual[i].bbox);
    EXPECT_EQ(expected[i].darkest, actual[i].darkest);
    EXPECT_EQ(expected[i].darkest_u, actual[i].darkest_u);
    EXPECT_EQ(expected[i].darkest_v, actual[i].darkest_v);
  }
}

// Noise and dots, with plateaus of equal grey levels (ties for the darkest pixel) and U shapes whose arms
// join only further down (labels merged late).
vpImage<unsigned char> TestImage(int width, int height, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<testing::Shape> shapes;
  std::uniform_real_distribution<double> u(0, width), v(0, height), r(1.5, 6);
  for (int k = 0; k < 12; ++k) shapes.push_back(testing::Disc({u(rng), v(rng)}, r(rng), 60));
  shapes.push_back(testing::Rect(5, 5, 8, 20, 50));
  shapes.push_back(testing::Rect(14, 5, 17, 20, 50));
  shapes.push_back(testing::Rect(5, 18, 17, 21, 50));
  vpImage<unsigned char> image = testing::Render(width, height, 190, shapes);
  std::uniform_int_distribution<int> noise(-12, 12);
  for (unsigned i = 0; i < image.getSize(); ++i) {
    if (i % 7 == 0) continue;  // some untouched plateau pixels
    image.bitmap[i] = static_cast<unsigned char>(std::clamp(image.bitmap[i] + noise(rng), 0, 255));
  }
  return image;
}

TEST(DarkComponents, RunLabellingMatchesPixelByPixelDefinition) {
  for (const auto& [w, h, window, offset] : std::vector<std::array<int, 4>>{
           {97, 61, 15, 8}, {64, 48, 41, 15}, {31, 7, 41, 5}, {5, 90, 3, 0}, {1, 1, 3, 0}, {40, 40, 81, 2}}) {
    SCOPED_TRACE(::testing::Message() << w << "x" << h << " window " << window << " offset " << offset);
    const vpImage<unsigned char> image = TestImage(w, h, static_cast<std::uint64_t>(w * 1000 + h));
    const std::vector<Component> expected = ReferenceComponents(image, window, offset);
    ExpectSame(expected, AdaptiveDarkComponents(image, window, offset));
    ExpectSame(expected, AdaptiveDarkComponentsWide(image, window, offset));
  }
}

TEST(DarkComponents, NarrowSumsEqualWideSumsOnAFullFrame) {
  const vpImage<unsigned char> image = TestImage(640, 480, 7);
  // 16-bit columns up to 257 rows, then 32-bit; sixteen pixels at a time while the box holds < 2^15 pixels
  // (181 x 181), one by one from 183 on.
  for (int window : {3, 41, 181, 183, 301, 481, 1001}) {
    SCOPED_TRACE(window);
    ExpectSame(AdaptiveDarkComponentsWide(image, window, 10), AdaptiveDarkComponents(image, window, 10));
  }
}

TEST(DarkComponents, GlobalThresholdMatchesDefinition) {
  const vpImage<unsigned char> image = TestImage(97, 61, 3);
  for (int threshold : {0, 120, 185, 255}) {
    SCOPED_TRACE(threshold);
    ExpectSame(ReferenceComponents(image, 3, 0, threshold), GlobalDarkComponents(image, threshold));
  }
}

}  // namespace
}  // namespace selfcal::tracking::internal
