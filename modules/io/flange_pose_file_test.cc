// Observations files of flange poses (version 1.1): the transform forms other tools write (matrix, rpy,
// theta-u / Rodrigues vector, ROS quaternion), the bit-identical round trip, and the refusals; the
// hand-eye result file.
#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "io/hand_eye_file.h"
#include "io/io_test_util.h"
#include "io/observations_file.h"
#include "io/transform_yaml.h"

namespace selfcal::io {
namespace {

using testing::TempDir;

constexpr char kHeader[] = R"(format: selfcal-observations
version: 1.1
camera: {width_px: 640, height_px: 480, fx_px: 600.0, cx_px: 319.5, cy_px: 239.5}
pixel_noise_px: 0.3
)";

std::string PoseYaml(const std::string& id, const std::string& flange) {
  return "  - id: " + id + "\n    base_from_flange: " + flange + "\n    dots: [[0, 100, 100], [1, 200, 150]]\n";
}

TEST(FlangePoseFile, EveryRotationFormReadsToTheSameFlangePose) {
  // One rotation of 0.5 rad about the unit axis (1, 2, 2) / 3, in every form.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.5, axis).toRotationMatrix();
  const Eigen::Quaterniond q(r);
  const Eigen::Vector3d rpy = RpyFromRotation(r);
  auto num = [](double v) {
    char b[40];
    std::snprintf(b, sizeof(b), "%.17g", v);
    return std::string(b);
  };
  const std::string t = "xyz_m: [0.4, -0.1, 0.6]";
  const std::string text = std::string(kHeader) + "yardsticks: []\nposes:\n" +
                           PoseYaml("a", "{" + t + ", rotvec_rad: [" + num(0.5 * axis.x()) + ", " + num(0.5 * axis.y()) +
                                             ", " + num(0.5 * axis.z()) + "]}") +
                           PoseYaml("b", "{" + t + ", quat_xyzw: [" + num(q.x()) + ", " + num(q.y()) + ", " +
                                             num(q.z()) + ", " + num(q.w()) + "]}") +
                           PoseYaml("c", "{xyz_mm: [400, -100, 600], rpy_rad: [" + num(rpy[0]) + ", " + num(rpy[1]) +
                                             ", " + num(rpy[2]) + "]}") +
                           PoseYaml("d", TransformYaml(Rigid3(r, Eigen::Vector3d(0.4, -0.1, 0.6)), TransformStyle::kExact));
  TempDir dir;
  const std::string path = dir.File("flange.yaml");
  testing::WriteFile(path, text);
  Result<ObservationSet> set = LoadObservations(path);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  ASSERT_TRUE(set->UsesFlangePoses());
  EXPECT_FALSE(set->flange_from_cam_known);
  EXPECT_EQ(set->robot.num_joints(), 0);
  for (const PoseObservation& pose : set->poses) {
    ASSERT_TRUE(pose.base_from_flange.has_value()) << pose.id;
    EXPECT_LT((pose.base_from_flange->rotation - r).norm(), 1e-14) << pose.id;
    EXPECT_LT((pose.base_from_flange->translation - Eigen::Vector3d(0.4, -0.1, 0.6)).norm(), 1e-15) << pose.id;
  }
  // Saved and loaded again: bit-identical, version 1.1, no robot block.
  const std::string saved = dir.File("saved.yaml");
  ASSERT_TRUE(SaveObservations(*set, saved).ok());
  const std::string bytes = testing::ReadFile(saved);
  EXPECT_NE(bytes.find("version: 1.1"), std::string::npos);
  EXPECT_EQ(bytes.find("robot:"), std::string::npos);
  Result<ObservationSet> again = LoadObservations(saved);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  for (size_t p = 0; p < set->poses.size(); ++p) {
    EXPECT_EQ(set->poses[p].base_from_flange->rotation, again->poses[p].base_from_flange->rotation);
    EXPECT_EQ(set->poses[p].base_from_flange->translation, again->poses[p].base_from_flange->translation);
  }
}

// Refusals, each naming the file, the pose and the key.
TEST(FlangePoseFile, BadFlangePosesAreRefusedByName) {
  TempDir dir;
  struct Case {
    std::string poses, expected;
  };
  const std::vector<Case> cases = {
      {PoseYaml("a", "{xyz_m: [0, 0, 1], quat_xyzw: [0, 0, 0, 2]}"), "has norm 2"},
      {PoseYaml("a", "{xyz_m: [0, 0, 1], quat_xyzw: [0, 0, 0, 1], rpy_deg: [0, 0, 0]}"), "both give the rotation"},
      {PoseYaml("a", "{xyz_m: [0, 0, 1]}"), "rotvec_rad"},
      {"  - id: a\n    base_from_flange: {xyz_m: [0, 0, 1], rpy_deg: [0, 0, 0]}\n    joints_deg: [1, 2]\n    dots: []\n",
       "both give the pose"},
      {PoseYaml("a", "{xyz_m: [0, 0, 1], rpy_deg: [0, 0, 0]}") + "  - id: b\n    joints_deg: [1, 2]\n    dots: []\n",
       "or `base_from_flange` in every pose"},
  };
  for (const Case& c : cases) {
    const std::string path = dir.File("bad.yaml");
    testing::WriteFile(path, std::string(kHeader) + "poses:\n" + c.poses);
    Result<ObservationSet> set = LoadObservations(path);
    ASSERT_FALSE(set.ok()) << c.poses;
    EXPECT_NE(set.status().message().find(c.expected), std::string::npos) << set.status().message();
    EXPECT_NE(set.status().message().find(path), std::string::npos) << set.status().message();
  }
}

TEST(HandEyeFile, SaveLoadRoundTripIsExact) {
  HandEyeResult result;
  result.flange_from_cam = Rigid3(Eigen::AngleAxisd(1.58, Eigen::Vector3d(0.01, 0.009, 1).normalized()).toRotationMatrix(),
                                  Eigen::Vector3d(0.0577, -0.0339, -0.0423));
  result.stddev << 1e-4, 2e-4, 3e-4, 1e-3, 2e-3, 3e-3;
  result.fx_px = 607.59;
  result.fx_stddev_px = 0.7;
  CameraIntrinsics camera;
  camera.fx_px = 607.59;
  camera.cx_px = 323.46;
  camera.k1 = 0.028;
  camera.k2 = -0.1 / 3;
  result.camera = camera;
  result.intrinsics_stddev[kFx] = 0.7;
  result.intrinsics_stddev[kK2] = 0.01 / 3;
  result.provenance = {{"method", "test"}};
  TempDir dir;
  const std::string path = dir.File("hand_eye.yaml");
  ASSERT_TRUE(SaveHandEye(result, path).ok());
  Result<HandEyeResult> loaded = LoadHandEye(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->flange_from_cam.rotation, result.flange_from_cam.rotation);
  EXPECT_EQ(loaded->flange_from_cam.translation, result.flange_from_cam.translation);
  EXPECT_EQ(loaded->fx_px, result.fx_px);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(loaded->stddev[k], result.stddev[k], 1e-15) << k;
  ASSERT_TRUE(loaded->camera.has_value());
  EXPECT_EQ(IntrinsicsOf(*loaded->camera), IntrinsicsOf(camera));
  EXPECT_EQ(loaded->intrinsics_stddev[kK2], result.intrinsics_stddev[kK2]);
  EXPECT_TRUE(std::isnan(loaded->intrinsics_stddev[kCx]));
  // A hand-edited rounded transform that no longer matches the exact one is caught.
  std::string text = testing::ReadFile(path);
  const size_t at = text.find("xyz_mm: [57.7");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, 13, "xyz_mm: [58.7");
  testing::WriteFile(path, text);
  EXPECT_FALSE(LoadHandEye(path).ok());
}

}  // namespace
}  // namespace selfcal::io
