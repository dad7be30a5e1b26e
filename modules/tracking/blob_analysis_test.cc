#include "tracking/blob_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace selfcal::tracking::internal {
namespace {

// RoundHalfAway is std::lround: at halves and their neighbours either side, both signs, small and large.
TEST(BlobAnalysis, RoundHalfAwayIsLround) {
  std::vector<double> xs = {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 4503599627370495.5, 4503599627370497.0, -1e15 - 0.5};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> any(-2000.0, 2000.0);
  for (int k = 0; k < 20000; ++k) {
    const double half = std::floor(any(rng)) + 0.5;
    xs.push_back(half);
    xs.push_back(std::nextafter(half, 1e9));
    xs.push_back(std::nextafter(half, -1e9));
    xs.push_back(any(rng));
  }
  for (double x : xs) EXPECT_EQ(RoundHalfAway(x), std::lround(x)) << x;
}

// The histogram's median is the sorted median (the mean of the middle two for an even count), for counts
// 1 to 400 of levels spread over 0-255 or crowded at either end.
TEST(BlobAnalysis, GreyHistogramMedianIsTheSortedMedian) {
  std::mt19937_64 rng(5);
  GreyHistogram histogram;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + trial % 400;
    const int low = trial % 3 == 0 ? 0 : (trial % 3 == 1 ? 200 : 0), high = trial % 3 == 2 ? 30 : 255;
    std::uniform_int_distribution<int> level(low, high);
    std::vector<int> values;
    histogram.Clear();
    for (int k = 0; k < n; ++k) {
      values.push_back(level(rng));
      histogram.Add(static_cast<unsigned char>(values.back()));
    }
    std::sort(values.begin(), values.end());
    const size_t mid = values.size() / 2;
    const double expected = values.size() % 2 == 0 ? 0.5 * (values[mid] + values[mid - 1]) : values[mid];
    ASSERT_EQ(histogram.Median(), expected) << "trial " << trial;
  }
  histogram.Clear();
  EXPECT_TRUE(std::isnan(histogram.Median()));
}

// DarkestAndMedian against its definition, pixel by pixel: the darkest level of one box, and the first
// level whose count from 0 reaches half of the other box's pixels; boxes narrow and wide (the sixteen-
// column steps and their overlapping last step), clipped by the image edges or wholly outside.
TEST(BlobAnalysis, DarkestAndMedianMatchTheirDefinition) {
  std::mt19937_64 rng(9);
  vpImage<unsigned char> image(97, 131);
  std::uniform_int_distribution<int> level(0, 255), coordinate(-20, 150), spread(0, 40);
  for (unsigned i = 0; i < image.getSize(); ++i) image.bitmap[i] = static_cast<unsigned char>(180 + spread(rng) / 3 - (i % 11 == 0 ? level(rng) / 2 : 0));
  auto box_at = [&] {
    const int a = coordinate(rng), b = coordinate(rng), c = coordinate(rng), d = coordinate(rng);
    return PixelBox{std::min(a, b), std::min(c, d), std::max(a, b), std::max(c, d)};
  };
  for (int trial = 0; trial < 4000; ++trial) {
    const PixelBox darkest_box = box_at(), median_box = box_at();
    int darkest = 255;
    std::vector<int> counts(256, 0);
    int n = 0;
    for (int v = 0; v < 97; ++v) {
      for (int u = 0; u < 131; ++u) {
        const int l = image[v][u];
        if (u >= darkest_box.u_min && u <= darkest_box.u_max && v >= darkest_box.v_min && v <= darkest_box.v_max) darkest = std::min(darkest, l);
        if (u >= median_box.u_min && u <= median_box.u_max && v >= median_box.v_min && v <= median_box.v_max) {
          ++counts[static_cast<size_t>(l)];
          ++n;
        }
      }
    }
    int median = 0;
    for (int seen = 0; median < 255; ++median) {
      seen += counts[static_cast<size_t>(median)];
      if (2 * seen >= n) break;
    }
    const Levels levels = DarkestAndMedian(image, darkest_box, median_box);
    ASSERT_EQ(levels.darkest, darkest) << "trial " << trial;
    ASSERT_EQ(levels.median, median) << "trial " << trial;
  }
}

}  // namespace
}  // namespace selfcal::tracking::internal
