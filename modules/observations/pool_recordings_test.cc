#include "observations/pool_recordings.h"

#include <gtest/gtest.h>

#include "support/test_robots.h"

namespace selfcal {
namespace {

ObservationSet TwoPoses() {
  ObservationSet set;
  set.robot = testing::Puma560();
  for (const char* id : {"pose_00", "pose_01"}) {
    PoseObservation pose;
    pose.id = id;
    pose.joints_rad = Eigen::VectorXd::Zero(set.robot.num_joints());
    pose.dots_px[1] = Eigen::Vector2d(100, 100);
    set.poses.push_back(pose);
  }
  return set;
}

// Two recordings with the same pose ids: every pose kept, its id prefixed, each recording a scene.
TEST(PoolRecordings, EachRecordingIsASceneWithItsPosesNamedApart) {
  ObservationSet second = TwoPoses();
  second.poses[1].scene = "left";
  const Result<ObservationSet> pooled = PoolRecordings({{"s1", TwoPoses()}, {"s3", second}});
  ASSERT_TRUE(pooled.ok()) << pooled.status().ToString();
  ASSERT_EQ(pooled->poses.size(), 4u);
  EXPECT_EQ(pooled->poses[0].id, "s1/pose_00");
  EXPECT_EQ(pooled->poses[0].scene, "s1");
  EXPECT_EQ(pooled->poses[2].id, "s3/pose_00");
  EXPECT_EQ(pooled->poses[2].scene, "s3");
  EXPECT_EQ(pooled->poses[3].scene, "s3/left");
  EXPECT_TRUE(pooled->Validate().empty()) << pooled->Validate();
}

// Another arm, another camera, or joints with flange poses cannot be one calibration: refused by name.
TEST(PoolRecordings, AnotherRobotOrCameraIsRefusedNamingTheRecording) {
  ObservationSet longer = TwoPoses();
  longer.robot.links[1].a += 0.001;
  Result<ObservationSet> pooled = PoolRecordings({{"s1", TwoPoses()}, {"s3", longer}});
  ASSERT_FALSE(pooled.ok());
  EXPECT_NE(pooled.status().ToString().find("recording `s3`"), std::string::npos) << pooled.status().ToString();
  EXPECT_NE(pooled.status().ToString().find("robot description"), std::string::npos) << pooled.status().ToString();
  ObservationSet wider = TwoPoses();
  wider.camera.width_px = 1280;
  pooled = PoolRecordings({{"s1", TwoPoses()}, {"s3", wider}});
  ASSERT_FALSE(pooled.ok());
  EXPECT_NE(pooled.status().ToString().find("1280 x 480"), std::string::npos) << pooled.status().ToString();
}

}  // namespace
}  // namespace selfcal
