#include "observations/observation_set.h"

#include <gtest/gtest.h>

#include "support/test_robots.h"

namespace selfcal {
namespace {

ObservationSet TwoPoses() {
  ObservationSet set;
  set.robot = testing::Puma560();
  PoseObservation a, b;
  a.id = "a";
  b.id = "b";
  a.joints_rad = b.joints_rad = Eigen::VectorXd::Zero(6);
  a.dots_px = {{1, {10, 20}}, {2, {30, 40}}, {5, {50, 60}}};
  b.dots_px = {{2, {31, 41}}, {5, {51, 61}}, {7, {1, 1}}};
  set.poses = {a, b};
  return set;
}

TEST(ObservationSet, MatchByIdNotByIndex) {
  const ObservationSet set = TwoPoses();
  const Matches m = MatchById(set.poses[0], set.poses[1]);
  ASSERT_EQ(m.dot_ids, (std::vector<int>{2, 5}));
  EXPECT_EQ(m.pixels_a[0], Eigen::Vector2d(30, 40));
  EXPECT_EQ(m.pixels_b[1], Eigen::Vector2d(51, 61));
}

TEST(ObservationSet, ValidateNamesPoseAndDot) {
  ObservationSet set = TwoPoses();
  EXPECT_EQ(set.Validate(), "");
  set.poses[1].id = "a";
  set.poses[0].joints_rad = Eigen::VectorXd::Zero(5);
  set.poses[1].dots_px[9] = Eigen::Vector2d(std::nan(""), 3);
  set.yardsticks.push_back({1, 99, 0.3});
  set.check_distances.push_back({2, 5, -1});
  const std::string problems = set.Validate();
  EXPECT_NE(problems.find("pose a: duplicate pose id"), std::string::npos) << problems;
  EXPECT_NE(problems.find("5 joint values"), std::string::npos) << problems;
  EXPECT_NE(problems.find("dot 9: non-finite pixel"), std::string::npos) << problems;
  EXPECT_NE(problems.find("dot 99 is never observed"), std::string::npos) << problems;
  EXPECT_NE(problems.find("check distance 2-5: length -1"), std::string::npos) << problems;
}

// A scene only verification poses see has no placed point: refused, named at its first pose (the set's
// unnamed scene too); every scene with an identification pose is fine.
TEST(ObservationSet, ValidateRefusesASceneNoIdentificationPoseSees) {
  ObservationSet set = TwoPoses();
  set.poses[1].scene = "moved";
  EXPECT_EQ(set.Validate(), "");
  set.poses[1].role = PoseRole::kVerification;
  EXPECT_NE(set.Validate().find("pose b: its scene `moved` is a scene that no identification pose sees"),
            std::string::npos)
      << set.Validate();
  set.poses[1].role = PoseRole::kIdentification;
  set.poses[0].role = PoseRole::kVerification;
  EXPECT_NE(set.Validate().find("pose a: the poses without a `scene` key see a scene that no identification pose"),
            std::string::npos)
      << set.Validate();
  set.poses[1].scene.clear();  // one scene again: a set of verification poses and one identification pose
  EXPECT_EQ(set.Validate(), "");
}

}  // namespace
}  // namespace selfcal

namespace selfcal {
namespace {

// Two recordings of one board that moved between them: the same dot ids are different points.
TEST(SeparateScenes, EachSceneGetsItsOwnDotsAndEveryKnownDistance) {
  ObservationSet set;
  for (const char* scene : {"s1", "s1", "s3", ""}) {
    PoseObservation pose;
    pose.id = std::string("p") + std::to_string(set.poses.size());
    pose.scene = scene;
    pose.dots_px[5] = Eigen::Vector2d(1, 2);
    pose.dots_px[18] = Eigen::Vector2d(3, 4);
    set.poses.push_back(pose);
  }
  set.yardsticks.push_back({5, 18, 0.198252});
  set.check_distances.push_back({5, 18, 0.2});
  std::vector<std::string> scenes;
  const ObservationSet out = SeparateScenes(set, &scenes);
  EXPECT_EQ(scenes, (std::vector<std::string>{"s1", "s3", ""}));
  EXPECT_EQ(out.poses[0].dots_px.begin()->first, 5);
  EXPECT_EQ(out.poses[1].dots_px.begin()->first, 5);
  EXPECT_EQ(out.poses[2].dots_px.begin()->first, kSceneDotStride + 5);
  EXPECT_EQ(out.poses[3].dots_px.rbegin()->first, 2 * kSceneDotStride + 18);
  EXPECT_EQ(out.poses[2].dots_px.at(kSceneDotStride + 18), Eigen::Vector2d(3, 4));
  ASSERT_EQ(out.yardsticks.size(), 3u);
  EXPECT_EQ(out.yardsticks[1].dot_a, kSceneDotStride + 5);
  EXPECT_EQ(out.yardsticks[2].dot_b, 2 * kSceneDotStride + 18);
  EXPECT_EQ(out.yardsticks[2].length_m, 0.198252);
  EXPECT_EQ(out.check_distances.size(), 3u);
  // One scene (named or not): the set as it is.
  for (PoseObservation& pose : set.poses) pose.scene = "only";
  const ObservationSet same = SeparateScenes(set, &scenes);
  EXPECT_EQ(same.poses[2].dots_px.begin()->first, 5);
  EXPECT_EQ(same.yardsticks.size(), 1u);
  EXPECT_EQ(scenes.size(), 1u);
}

}  // namespace
}  // namespace selfcal
