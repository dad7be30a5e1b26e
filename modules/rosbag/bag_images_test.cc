// The still-image rule of bag_images.h on synthetic joint readings at 100 Hz: images where the arm is
// still get the nearest reading, images while moving or at the edge of a still stretch are left out, and
// a still image far from every reading is left out with a note.
#include "rosbag/bag_images.h"

#include <gtest/gtest.h>

namespace selfcal::rosbag {
namespace {

// Two joints: still at 0 until 1 s, moving to 1 rad until 2 s, still until 3 s, then a 0.5 s gap, still.
std::vector<JointSample> Readings() {
  std::vector<JointSample> joints;
  for (int k = 0; k <= 300; ++k) {
    const double t = 0.01 * k;
    const double q = t < 1 ? 0 : t < 2 ? t - 1 : 1;
    joints.push_back({t, Eigen::Vector2d(q, -q)});
  }
  for (int k = 0; k <= 100; ++k) joints.push_back({3.5 + 0.01 * k, Eigen::Vector2d(1, -1)});
  return joints;
}

TEST(BagImages, StillImagesMatchedToTheNearestReadingAndMovingOnesLeftOut) {
  BagOptions options;
  int moving = 0;
  std::vector<std::string> notes;
  const std::vector<int> matched =
      MatchStillImages(Readings(), {0.5, 0.504, 1.5, 1.9, 2.5, 1.05, 0.95, 0.05}, options, &moving, &notes);
  EXPECT_EQ(matched, (std::vector<int>{50, 50, -1, -1, 250, -1, -1, -1}));
  EXPECT_EQ(moving, 5);  // 1.5, 1.9 moving; 1.05 and 0.95 see the motion within 0.2 s; 0.05 lacks readings 0.1 s before
  EXPECT_TRUE(notes.empty());
}

TEST(BagImages, AStillImageFarFromEveryReadingIsLeftOutWithANote) {
  // Readings every 0.12 s, still: covered either side, but an image 0.06 s from the nearest.
  std::vector<JointSample> sparse;
  for (int k = 0; k < 20; ++k) sparse.push_back({0.12 * k, Eigen::Vector2d(1, 1)});
  BagOptions options;
  int moving = 0;
  std::vector<std::string> notes;
  EXPECT_EQ(MatchStillImages(sparse, {1.26, 1.2}, options, &moving, &notes), (std::vector<int>{-1, 10}));
  EXPECT_EQ(moving, 0);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("0.060 s away"), std::string::npos) << notes[0];
}

TEST(BagImages, ATinyDriftBelowTheToleranceIsStillAndOneAboveIsNot) {
  std::vector<JointSample> drift;
  for (int k = 0; k < 100; ++k) drift.push_back({0.01 * k, Eigen::Vector2d(0.5e-6 * k, 0)});  // 5e-5 rad / s
  BagOptions options;
  int moving = 0;
  std::vector<std::string> notes;
  EXPECT_EQ(MatchStillImages(drift, {0.5}, options, &moving, &notes), (std::vector<int>{50}));
  options.still_tolerance_rad = 1e-5;
  EXPECT_EQ(MatchStillImages(drift, {0.5}, options, &moving, &notes), (std::vector<int>{-1}));
}

}  // namespace
}  // namespace selfcal::rosbag
