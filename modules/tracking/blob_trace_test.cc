#include "tracking/blob_trace.h"

#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <visp3/core/vpException.h>

#include "tracking/tracking_test_util.h"

namespace selfcal::tracking::internal {
namespace {

struct Outcome {
  bool thrown = false;
  std::string message;
  TracedBlob blob;
};

template <typename Trace>
Outcome Attempt(Trace trace) {
  Outcome o;
  try {
    o.blob = trace();
  } catch (const vpException& e) {
    o.thrown = true;
    o.message = e.getMessage();
  }
  return o;
}

// TrackDarkBlob (the border following, vpDot2 where it fails) against vpDot2 alone, from half the dark
// pixels and a few light ones, some off the pixel centre, at two thresholds and three previous sizes (0: the
// detector's initTracking): the same blobs to the bit (bounding box, centre of gravity, area) and the
// same failures.
TEST(BlobTrace, FollowBorderGivesVpDot2sBlobs) {
  int compared = 0, followed = 0, searched_or_thrown = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const vpImage<unsigned char> image = testing::RandomDarkShapes(seed, 160, 120, 40, seed % 2 == 0 ? 3.0 : 0.0);
    for (int threshold : {70, 160}) {
      for (double size : {0.0, 3.0, 9.0}) {
        for (int v = 0; v < 120; ++v) {
          for (int u = 0; u < 160; ++u) {
            // Half the dark pixels; one light start in 300 (vpDot2's window search, slow).
            if (static_cast<int>(image[v][u]) > threshold ? (u + 7 * v) % 300 != 0 : (u + v) % 2 != 0) continue;
            const Eigen::Vector2d start(u + (size == 3.0 ? 0.7 : 0.0), v + (size == 9.0 ? 0.4 : 0.0));
            const Outcome fast = Attempt([&] { return TrackDarkBlob(image, threshold, start, size, size); });
            const Outcome reference = Attempt([&] { return TrackDarkBlobWithVpDot2(image, threshold, start, size, size); });
            TracedBlob followed_blob;
            if (FollowBorder(image, threshold, start, size, &followed_blob)) {
              ++followed;
            } else {
              ++searched_or_thrown;
            }
            ++compared;
            const std::string where = "seed " + std::to_string(seed) + " T " + std::to_string(threshold) + " size " +
                                      std::to_string(size) + " start " + std::to_string(u) + "," + std::to_string(v);
            ASSERT_EQ(fast.thrown, reference.thrown) << where;
            EXPECT_EQ(fast.message, reference.message) << where;
            if (fast.thrown) continue;
            EXPECT_EQ(fast.blob.bbox, reference.blob.bbox) << where;
            // Bit for bit: the same float increments summed in the same order.
            EXPECT_EQ(fast.blob.cog_px.x(), reference.blob.cog_px.x()) << where;
            EXPECT_EQ(fast.blob.cog_px.y(), reference.blob.cog_px.y()) << where;
            EXPECT_EQ(fast.blob.polygon_area_px2, reference.blob.polygon_area_px2) << where;
          }
        }
      }
    }
  }
  // Both paths are exercised: most starts on a blob are followed, the others are vpDot2's.
  EXPECT_GT(followed, 5000);
  EXPECT_GT(searched_or_thrown, 1000);
  std::cout << "[ blob trace ] " << compared << " starts: " << followed << " followed, " << searched_or_thrown
            << " left to vpDot2\n";
}

// Where FollowBorder gives a blob, vpDot2 gives the same one: a small blob far from the origin, whose
// float increments (u^2 / 2 at u ~ 600) lose digits, still matches to the bit.
TEST(BlobTrace, FarFromTheOriginSameBits) {
  std::vector<testing::Shape> shapes;
  for (int k = 0; k < 12; ++k) {
    shapes.push_back(testing::Disc(Eigen::Vector2d(500 + 11.3 * k, 430 + 3.7 * k), 2.2 + 0.4 * k, 30));
  }
  const vpImage<unsigned char> image = testing::Render(640, 480, 210, shapes, 8, 1.0, 5);
  int followed = 0;
  for (int k = 0; k < 12; ++k) {
    const Eigen::Vector2d start(500 + 11.3 * k, 430 + 3.7 * k);
    TracedBlob blob;
    ASSERT_TRUE(FollowBorder(image, 120, start, 0, &blob)) << k;
    ++followed;
    const TracedBlob reference = TrackDarkBlobWithVpDot2(image, 120, start, 0, 0);
    EXPECT_EQ(blob.bbox, reference.bbox) << k;
    EXPECT_EQ(blob.cog_px.x(), reference.cog_px.x()) << k;
    EXPECT_EQ(blob.cog_px.y(), reference.cog_px.y()) << k;
    EXPECT_EQ(blob.polygon_area_px2, reference.polygon_area_px2) << k;
  }
  EXPECT_EQ(followed, 12);
}

}  // namespace
}  // namespace selfcal::tracking::internal
