// Eye-to-hand in the files (issue 40): the observations file's `configuration` and `base_from_cam` for flange
// poses and for joint angles, their round trips, the refusals of the other configuration's camera key; the
// calibrated model and the hand-eye result with the fixed camera.
#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "io/hand_eye_file.h"
#include "io/io_test_util.h"
#include "io/observations_file.h"
#include "io/robot_config.h"
#include "io/transform_yaml.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using testing::MessageHas;
using testing::TempDir;

constexpr char kCamera[] = "camera: {width_px: 640, height_px: 480, fx_px: 600.0, cx_px: 319.5, cy_px: 239.5}\n"
                           "pixel_noise_px: 0.3\n";

std::string FlangePoses() {
  return "poses:\n"
         "  - id: a\n    base_from_flange: {xyz_m: [0.4, -0.1, 0.6], rotvec_rad: [0.1, 0.2, 0.3]}\n"
         "    dots: [[0, 100, 100], [1, 200, 150]]\n"
         "  - id: b\n    base_from_flange: {xyz_m: [0.5, 0.1, 0.5], rotvec_rad: [0.3, -0.2, 0.1]}\n"
         "    dots: [[0, 110, 120], [1, 210, 170]]\n";
}

std::string JointPoses() {
  return "yardsticks: [{dot_a: 0, dot_b: 1, length_mm: 48}]\nposes:\n"
         "  - id: a\n    joints_deg: [0, 30, -150, 0, 45, 0]\n    dots: [[0, 100, 100], [1, 200, 150]]\n"
         "  - id: b\n    joints_deg: [10, 35, -155, 5, 40, -10]\n    dots: [[0, 110, 120], [1, 210, 170]]\n";
}

constexpr char kFixedCamera[] = "base_from_cam: {xyz_mm: [954, -51.2, 476.2], rotvec_rad: [-1.1041, -1.1127, 1.2895]}\n";

Rigid3 PublishedBaseFromCam() {
  const Eigen::Vector3d rotvec(-1.1041, -1.1127, 1.2895);
  return Rigid3(Eigen::AngleAxisd(rotvec.norm(), rotvec.normalized()).toRotationMatrix(),
                Eigen::Vector3d(0.954, -0.0512, 0.4762));
}

Result<ObservationSet> LoadText(const TempDir& dir, const std::string& text, std::string* path) {
  *path = dir.File("obs.yaml");
  testing::WriteFile(*path, text);
  return LoadObservations(*path);
}

// Saved and loaded again: the same bytes a second time, and the mount and fixed camera kept bit for bit.
void ExpectRoundTrip(const TempDir& dir, const ObservationSet& set) {
  const std::string saved = dir.File("saved.yaml"), again = dir.File("again.yaml");
  ASSERT_TRUE(SaveObservations(set, saved).ok());
  const std::string bytes = testing::ReadFile(saved);
  EXPECT_NE(bytes.find("version: 1.2\nconfiguration: eye_to_hand\n"), std::string::npos) << bytes;
  EXPECT_EQ(bytes.find("\nflange_from_cam:"), std::string::npos) << bytes;
  Result<ObservationSet> loaded = LoadObservations(saved);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->robot.mount, CameraMount::kEyeToHand);
  EXPECT_EQ(loaded->flange_from_cam_known, set.flange_from_cam_known);
  EXPECT_EQ(loaded->robot.base_from_cam.rotation, set.robot.base_from_cam.rotation);
  EXPECT_EQ(loaded->robot.base_from_cam.translation, set.robot.base_from_cam.translation);
  ASSERT_TRUE(SaveObservations(*loaded, again).ok());
  EXPECT_EQ(bytes, testing::ReadFile(again));
}

TEST(EyeToHandFile, FlangePosesWithAndWithoutTheFixedCameraLoadAndRoundTrip) {
  TempDir dir;
  std::string path;
  const std::string head = "format: selfcal-observations\nversion: 1.2\nconfiguration: eye_to_hand\n";
  Result<ObservationSet> with = LoadText(dir, head + kFixedCamera + kCamera + FlangePoses(), &path);
  ASSERT_TRUE(with.ok()) << with.status().ToString();
  EXPECT_TRUE(with->UsesFlangePoses());
  EXPECT_EQ(with->robot.mount, CameraMount::kEyeToHand);
  EXPECT_TRUE(with->flange_from_cam_known);  // the nominal camera transform, here the fixed one, was given
  const Rigid3 published = PublishedBaseFromCam();
  EXPECT_LT((with->robot.base_from_cam.translation - published.translation).norm(), 1e-15);
  EXPECT_LT((with->robot.base_from_cam.rotation - published.rotation).norm(), 1e-14);
  EXPECT_EQ(with->robot.flange_from_cam.translation, Eigen::Vector3d::Zero());
  ExpectRoundTrip(dir, *with);

  Result<ObservationSet> without = LoadText(dir, head + kCamera + FlangePoses(), &path);
  ASSERT_TRUE(without.ok()) << without.status().ToString();
  EXPECT_EQ(without->robot.mount, CameraMount::kEyeToHand);
  EXPECT_FALSE(without->flange_from_cam_known);  // the start estimates the fixed camera
  ExpectRoundTrip(dir, *without);
  EXPECT_EQ(testing::ReadFile(dir.File("saved.yaml")).find("base_from_cam"), std::string::npos);

  // Without the key the set is eye-in-hand, as every file before version 1.2.
  Result<ObservationSet> plain = LoadText(dir, "format: selfcal-observations\nversion: 1.1\n" + std::string(kCamera) +
                                                   FlangePoses(), &path);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  EXPECT_EQ(plain->robot.mount, CameraMount::kEyeInHand);
  ASSERT_TRUE(SaveObservations(*plain, dir.File("plain.yaml")).ok());
  const std::string bytes = testing::ReadFile(dir.File("plain.yaml"));
  EXPECT_NE(bytes.find("version: 1.1\n"), std::string::npos);
  EXPECT_EQ(bytes.find("configuration"), std::string::npos);
}

TEST(EyeToHandFile, JointAnglesOnARobotLoadAndRoundTrip) {
  TempDir dir;
  std::string path;
  const std::string head = "format: selfcal-observations\nversion: 1.2\nconfiguration: eye_to_hand\nrobot_file: " +
                           testing::SourcePath("config/robots/puma560.yaml") + "\n";
  Result<ObservationSet> set = LoadText(dir, head + kFixedCamera + kCamera + JointPoses(), &path);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_FALSE(set->UsesFlangePoses());
  EXPECT_EQ(set->robot.num_joints(), 6);
  EXPECT_EQ(set->robot.mount, CameraMount::kEyeToHand);
  EXPECT_TRUE(set->flange_from_cam_known);
  EXPECT_LT((set->robot.base_from_cam.translation - PublishedBaseFromCam().translation).norm(), 1e-15);
  ExpectRoundTrip(dir, *set);

  Result<ObservationSet> without = LoadText(dir, head + kCamera + JointPoses(), &path);
  ASSERT_TRUE(without.ok()) << without.status().ToString();
  EXPECT_FALSE(without->flange_from_cam_known);
  ExpectRoundTrip(dir, *without);
}

// The other configuration's camera key, or an unknown configuration: refused naming the file, the line and
// the key, whatever the poses.
TEST(EyeToHandFile, TheOtherConfigurationsCameraKeyIsRefusedNamingFileLineAndKey) {
  TempDir dir;
  struct Case {
    std::string text, expected;
  };
  const std::string robot = "robot_file: " + testing::SourcePath("config/robots/puma560.yaml") + "\n";
  const std::string e2h = "format: selfcal-observations\nversion: 1.2\nconfiguration: eye_to_hand\n";
  const std::string e2h_flange = "flange_from_cam: {xyz_mm: [0, 0, 60], rpy_deg: [0, 0, 90]}\n";
  const std::vector<Case> cases = {
      {e2h + e2h_flange + kCamera + FlangePoses(), "`flange_from_cam` at %:4 does not fit `configuration: eye_to_hand` (at %:3)"},
      {e2h + robot + e2h_flange + kCamera + JointPoses(), "`flange_from_cam` at %:5 does not fit `configuration: eye_to_hand`"},
      {"format: selfcal-observations\nversion: 1.1\n" + std::string(kFixedCamera) + kCamera + FlangePoses(),
       "`base_from_cam` at %:3 does not fit `configuration: eye_in_hand` (the default)"},
      {"format: selfcal-observations\nversion: 1.2\nconfiguration: eye_in_hand\n" + robot + kFixedCamera + kCamera + JointPoses(),
       "`base_from_cam` at %:5 does not fit `configuration: eye_in_hand` (at %:3)"},
      {"format: selfcal-observations\nversion: 1.2\nconfiguration: eye-to-hand\n" + std::string(kCamera) + FlangePoses(),
       "`configuration` = `eye-to-hand` at %:3 must be eye_in_hand or eye_to_hand"},
  };
  for (const Case& c : cases) {
    std::string path;
    Result<ObservationSet> set = LoadText(dir, c.text, &path);
    ASSERT_FALSE(set.ok()) << c.text;
    EXPECT_EQ(set.status().code(), ErrorCode::kInvalidInput);
    std::string expected = c.expected;
    for (size_t at; (at = expected.find('%')) != std::string::npos;) expected.replace(at, 1, path);
    EXPECT_TRUE(MessageHas(set.status(), expected)) << c.text;
  }
}

TEST(EyeToHandFile, TheCalibratedModelKeepsTheConfigurationAndTheFixedCamera) {
  CalibratedModel calibrated;
  calibrated.model = selfcal::testing::Puma560();
  calibrated.model.mount = CameraMount::kEyeToHand;
  calibrated.model.base_from_cam = PublishedBaseFromCam();
  calibrated.fx_px = 601.07;
  TempDir dir;
  const std::string path = dir.File("calibrated_model.yaml");
  ASSERT_TRUE(SaveCalibratedModel(calibrated, path).ok());
  const std::string bytes = testing::ReadFile(path);
  EXPECT_NE(bytes.find("version: 1.1\n"), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("configuration: eye_to_hand"), std::string::npos) << bytes;
  Result<CalibratedModel> loaded = LoadCalibratedModel(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->model.mount, CameraMount::kEyeToHand);
  // Written in mm and degrees with the shortest exact decimals: back to rounding.
  EXPECT_LT((loaded->model.base_from_cam.translation - calibrated.model.base_from_cam.translation).norm(), 1e-15);
  EXPECT_LT((loaded->model.base_from_cam.rotation - calibrated.model.base_from_cam.rotation).norm(), 1e-14);

  // An observations file on this model as its robot_file is eye-to-hand without saying so, with its fixed camera
  // as the nominal; saying eye_in_hand contradicts it.
  const std::string head = "format: selfcal-observations\nversion: 1.2\nrobot_file: " + path + "\n";
  std::string obs_path;
  Result<ObservationSet> set = LoadText(dir, head + kCamera + JointPoses(), &obs_path);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->robot.mount, CameraMount::kEyeToHand);
  EXPECT_TRUE(set->flange_from_cam_known);
  Result<ObservationSet> contradicted =
      LoadText(dir, head + "configuration: eye_in_hand\n" + kCamera + JointPoses(), &obs_path);
  EXPECT_TRUE(MessageHas(contradicted.status(), "but the robot is a calibrated eye_to_hand model"));

  // The fixed camera belongs to eye_to_hand only; an eye-in-hand model without the key reads as before.
  std::string text = bytes;
  text.replace(text.find("configuration: eye_to_hand"), 26, "configuration: eye_in_hand");
  testing::WriteFile(path, text);
  EXPECT_TRUE(MessageHas(LoadCalibratedModel(path).status(), "only with `configuration: eye_to_hand`"));
  calibrated.model.mount = CameraMount::kEyeInHand;
  ASSERT_TRUE(SaveCalibratedModel(calibrated, path).ok());
  EXPECT_EQ(testing::ReadFile(path).find("configuration"), std::string::npos);
  Result<CalibratedModel> eye_in_hand = LoadCalibratedModel(path);
  ASSERT_TRUE(eye_in_hand.ok()) << eye_in_hand.status().ToString();
  EXPECT_EQ(eye_in_hand->model.mount, CameraMount::kEyeInHand);
}

TEST(EyeToHandFile, TheHandEyeResultGivesTheFixedCamera) {
  HandEyeResult result;
  result.mount = CameraMount::kEyeToHand;
  result.base_from_cam = PublishedBaseFromCam();
  result.stddev << 1e-3, 2e-3, 3e-3, 1e-2, 2e-2, 3e-2;
  result.fx_px = 601.07;
  TempDir dir;
  const std::string path = dir.File("hand_eye.yaml");
  ASSERT_TRUE(SaveHandEye(result, path).ok());
  const std::string bytes = testing::ReadFile(path);
  EXPECT_NE(bytes.find("configuration: eye_to_hand\n"), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("base_from_cam: {xyz_mm: [954, -51.2, 476.2"), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("base_from_cam_quat_xyzw: "), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("base_from_cam_stddev: {xyz_mm: [1, 2, 3]"), std::string::npos) << bytes;
  EXPECT_EQ(bytes.find("flange_from_cam"), std::string::npos) << bytes;
  Result<HandEyeResult> loaded = LoadHandEye(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->mount, CameraMount::kEyeToHand);
  EXPECT_EQ(loaded->base_from_cam.rotation, result.base_from_cam.rotation);
  EXPECT_EQ(loaded->base_from_cam.translation, result.base_from_cam.translation);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(loaded->stddev[k], result.stddev[k], 1e-15) << k;
}

}  // namespace
}  // namespace selfcal::io
