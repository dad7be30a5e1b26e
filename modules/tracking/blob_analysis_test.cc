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

}  // namespace
}  // namespace selfcal::tracking::internal
