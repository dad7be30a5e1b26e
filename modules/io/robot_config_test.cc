// Robot configs and calibrated models: the shipped configs match the robots of the test support, and a
// calibrated model survives a save / load.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "io/transform_yaml.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath
using selfcal::testing::RigidNear;

Eigen::VectorXd RandomJoints(const RobotModel& model, std::mt19937_64* rng) {
  Eigen::VectorXd q(model.num_joints());
  for (int j = 0; j < q.size(); ++j) {
    std::uniform_real_distribution<double> in_limits(model.limits[j].min_rad, model.limits[j].max_rad);
    q[j] = in_limits(*rng);
  }
  return q;
}

// Forward kinematics to the camera agree to 1e-12 (m and rad) at random joint angles.
void ExpectSameKinematics(const RobotModel& expected, const RobotModel& actual, std::mt19937_64* rng) {
  ASSERT_EQ(expected.num_joints(), actual.num_joints());
  for (int j = 0; j < expected.num_joints(); ++j) {
    EXPECT_NEAR(expected.limits[j].min_rad, actual.limits[j].min_rad, 1e-12) << "joint " << j + 1;
    EXPECT_NEAR(expected.limits[j].max_rad, actual.limits[j].max_rad, 1e-12) << "joint " << j + 1;
  }
  const Eigen::VectorXd rho_expected = KinematicParameters::Nominal(expected);
  const Eigen::VectorXd rho_actual = KinematicParameters::Nominal(actual);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::VectorXd q = RandomJoints(expected, rng);
    EXPECT_TRUE(RigidNear(BaseFromCam(expected, rho_expected, q), BaseFromCam(actual, rho_actual, q), 1e-12, 1e-12))
        << "q = " << q.transpose();
  }
}

TEST(RobotConfig, ShippedPuma560MatchesTestSupport) {
  std::mt19937_64 rng(1);
  Result<RobotModel> loaded = LoadRobotModel(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->name, "puma560");
  ExpectSameKinematics(selfcal::testing::Puma560(), *loaded, &rng);
}

// The limits the config cites: Corke, Robotics Toolbox for MATLAB, mdl_puma560.m,
// qlim = [-160 160; -45 225; -225 45; -110 170; -100 100; -266 266] deg (q2 is the shoulder, q3 the elbow:
// with q2 and q3 swapped, every trajectory bends the elbow where a real PUMA cannot).
TEST(RobotConfig, ShippedPuma560LimitsAreCorkesQlim) {
  const double qlim_deg[6][2] = {{-160, 160}, {-45, 225}, {-225, 45}, {-110, 170}, {-100, 100}, {-266, 266}};
  Result<RobotModel> loaded = LoadRobotModel(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->limits.size(), 6u);
  const RobotModel support = selfcal::testing::Puma560();
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(loaded->limits[j].min_rad, DegToRad(qlim_deg[j][0]), 1e-12) << "joint " << j + 1;
    EXPECT_NEAR(loaded->limits[j].max_rad, DegToRad(qlim_deg[j][1]), 1e-12) << "joint " << j + 1;
    EXPECT_NEAR(support.limits[j].min_rad, DegToRad(qlim_deg[j][0]), 1e-12) << "test support, joint " << j + 1;
    EXPECT_NEAR(support.limits[j].max_rad, DegToRad(qlim_deg[j][1]), 1e-12) << "test support, joint " << j + 1;
  }
}

TEST(RobotConfig, ShippedUr5eMatchesTestSupport) {
  std::mt19937_64 rng(2);
  Result<RobotModel> loaded = LoadRobotModel(SourcePath("config/robots/ur5e.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->name, "ur5e");
  ExpectSameKinematics(selfcal::testing::Ur5e(), *loaded, &rng);
}

TEST(RobotConfig, RpyConventionIsRzRyRx) {
  const double roll = 0.3, pitch = -0.7, yaw = 2.1;
  const Eigen::Matrix3d r = RotationFromRpy(roll, pitch, yaw);
  EXPECT_TRUE(r.isApprox(RotZ(yaw) * RotY(pitch) * RotX(roll), 1e-15));
  EXPECT_TRUE(RpyFromRotation(r).isApprox(Eigen::Vector3d(roll, pitch, yaw), 1e-14));
  // Gimbal lock: the angles differ but the rotation is reproduced.
  for (const double p : {kPi / 2, -kPi / 2}) {
    const Eigen::Matrix3d locked = RotationFromRpy(0.4, p, -1.1);
    const Eigen::Vector3d rpy = RpyFromRotation(locked);
    EXPECT_LT((RotationFromRpy(rpy[0], rpy[1], rpy[2]) - locked).norm(), 1e-14);
  }
}

TEST(RobotConfig, ModifiedConventionMatchesItsStandardEquivalent) {
  // Craig's modified DH of the PUMA: alpha_{i-1}, a_{i-1} move one row down.
  const std::string text =
      "name: puma560\n"
      "dh_convention: modified\n"
      "joints:\n"
      "  - {a_mm: 0, alpha_deg: 0, d_mm: 0, min_deg: -160, max_deg: 160}\n"
      "  - {a_mm: 0, alpha_deg: 90, d_mm: 0, min_deg: -45, max_deg: 225}\n"
      "  - {a_m: 0.4318, alpha_deg: 0, d_m: 0.15005, min_deg: -225, max_deg: 45}\n"
      "  - {a_mm: 20.3, alpha_rad: -1.5707963267948966, d_mm: 431.8, min_deg: -110, max_deg: 170}\n"
      "  - {a_mm: 0, alpha_deg: 90, d_mm: 0, min_deg: -100, max_deg: 100}\n"
      "  - {a_mm: 0, alpha_deg: -90, d_mm: 0, min_deg: -266, max_deg: 266}\n"
      "flange_from_cam: {xyz_mm: [40, 0, 60], rotation: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}\n";
  TempDir dir;
  WriteFile(dir.File("modified.yaml"), text);
  Result<RobotModel> loaded = LoadRobotModel(dir.File("modified.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  std::mt19937_64 rng(3);
  ExpectSameKinematics(selfcal::testing::Puma560(), *loaded, &rng);
}

TEST(RobotConfig, BetaNeedsTheHayatiConvention) {
  TempDir dir;
  std::string text = ReadFile(SourcePath("config/robots/puma560.yaml"));
  text.replace(text.find("theta_offset_deg: 0.0, min_deg: -45"), 21, "beta_deg: 0.1");
  WriteFile(dir.File("beta.yaml"), text);
  const Status status = LoadRobotModel(dir.File("beta.yaml")).status();
  EXPECT_NE(status.message().find("`joints[1].beta_deg` at " + dir.File("beta.yaml") + ":14 is not allowed here: a Hayati "
                                  "beta needs dh_convention: modified_hayati"),
            std::string::npos)
      << status.message();
}

TEST(RobotConfig, NotARotationMatrixIsRefused) {
  TempDir dir;
  std::string text = ReadFile(SourcePath("config/robots/puma560.yaml"));
  text.replace(text.find("rpy_deg: [0, 0, 90]"), 19, "rotation: [[1, 0, 0], [0, 1, 0], [0, 0, -1]]");
  WriteFile(dir.File("reflection.yaml"), text);
  const Status status = LoadRobotModel(dir.File("reflection.yaml")).status();
  EXPECT_NE(status.message().find("`flange_from_cam.rotation` at " + dir.File("reflection.yaml") + ":21 is not a rotation"),
            std::string::npos)
      << status.message();
}

CalibratedModel PerturbedPuma(std::mt19937_64* rng, Eigen::VectorXd* rho_out) {
  const RobotModel nominal = selfcal::testing::Puma560();
  const KinematicParameters params(nominal.num_joints());
  Eigen::VectorXd rho = KinematicParameters::Nominal(nominal);
  std::normal_distribution<double> length(0.0, 1e-3), angle(0.0, DegToRad(0.2));
  for (int i = 0; i < params.size(); ++i) rho[i] += params.kind(i) == ParameterKind::kLength ? length(*rng) : angle(*rng);
  CalibratedModel calibrated;
  calibrated.model = ApplyParameters(nominal, rho);
  calibrated.source = "unit test \"perturbed\" puma";
  calibrated.fx_px = 1000.0 / 3.0;
  CameraIntrinsics camera;
  camera.fx_px = calibrated.fx_px;
  camera.mu = 1.0 + 1e-4 / 3;
  camera.cx_px = 321.1 / 3;
  camera.k1 = -0.1 / 7;
  camera.p2 = 1e-3 / 3;
  calibrated.camera = camera;
  calibrated.intrinsics_stddev[kFx] = 0.3;
  calibrated.intrinsics_stddev[kP2] = 1e-4 / 3;
  calibrated.parameters = rho;
  calibrated.provenance = {{"software", "selfcal 0.1.0"}, {"session", "s-0007"}, {"odd key: #1", "tab\there"}};
  *rho_out = rho;
  return calibrated;
}

TEST(CalibratedModel, SaveLoadRoundTripKeepsBetasOffsetsAndKinematics) {
  std::mt19937_64 rng(4);
  Eigen::VectorXd rho;
  const CalibratedModel saved = PerturbedPuma(&rng, &rho);
  ASSERT_NE(saved.model.links[2].beta, 0.0);
  TempDir dir;
  const std::string path = dir.File("calibrated.yaml");
  ASSERT_TRUE(SaveCalibratedModel(saved, path).ok());
  Result<CalibratedModel> loaded = LoadCalibratedModel(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString() << "\n" << ReadFile(path);
  EXPECT_EQ(loaded->model.name, "puma560");
  EXPECT_EQ(loaded->source, saved.source);
  EXPECT_EQ(loaded->fx_px, saved.fx_px);
  EXPECT_EQ(loaded->provenance, saved.provenance);
  // The camera and the intrinsics' sigmas come back bit for bit; the held ones' sigmas stay absent.
  ASSERT_TRUE(loaded->camera.has_value()) << ReadFile(path);
  EXPECT_EQ(IntrinsicsOf(*loaded->camera), IntrinsicsOf(*saved.camera));
  EXPECT_EQ(loaded->camera->width_px, saved.camera->width_px);
  for (int k = 0; k < kNumIntrinsics; ++k) {
    const double a = saved.intrinsics_stddev[k], b = loaded->intrinsics_stddev[k];
    EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << IntrinsicName(k) << " " << a << " " << b;
  }
  ASSERT_EQ(loaded->parameters.size(), rho.size());
  EXPECT_LT((loaded->parameters - rho).cwiseAbs().maxCoeff(), 1e-14);
  for (int i = 0; i < saved.model.num_joints(); ++i) {
    const LinkParameters& a = saved.model.links[i];
    const LinkParameters& b = loaded->model.links[i];
    EXPECT_NEAR(a.alpha, b.alpha, 1e-15);
    EXPECT_NEAR(a.a, b.a, 1e-15);
    EXPECT_NEAR(a.beta, b.beta, 1e-15);
    EXPECT_NEAR(a.theta, b.theta, 1e-15);
    EXPECT_NEAR(a.d, b.d, 1e-15);
  }
  EXPECT_TRUE(RigidNear(saved.model.link_n_from_flange, loaded->model.link_n_from_flange, 1e-14, 1e-15));
  ExpectSameKinematics(saved.model, loaded->model, &rng);
  // The plain loader reads the calibrated file too.
  Result<RobotModel> as_robot = LoadRobotModel(path);
  ASSERT_TRUE(as_robot.ok()) << as_robot.status().ToString();
  ExpectSameKinematics(saved.model, *as_robot, &rng);
}

TEST(CalibratedModel, WrittenInMillimetresAndDegreesWithSchema) {
  std::mt19937_64 rng(5);
  Eigen::VectorXd rho;
  TempDir dir;
  const std::string path = dir.File("calibrated.yaml");
  ASSERT_TRUE(SaveCalibratedModel(PerturbedPuma(&rng, &rho), path).ok());
  const std::string text = ReadFile(path);
  for (const char* expected : {"format: selfcal-calibrated-model\n", "version: 1\n", "dh_convention: modified_hayati\n",
                               "alpha_deg: ", "a_mm: ", "beta_deg: ", "theta_offset_deg: ", "d_mm: ",
                               "link_n_from_flange: {xyz_mm: ", "flange_from_cam: {xyz_mm: ", "fx_px: 333.3333333333333\n",
                               "  j2.a_mm: ", "  cam.rz_deg: ", "camera: {width_px: 640, height_px: 480, fx_px: 333.3333333333333",
                               "intrinsics_stddev: {fx_px: 0.3, p2: "}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  }
}

TEST(CalibratedModel, UnknownMajorVersionIsRefused) {
  std::mt19937_64 rng(6);
  Eigen::VectorXd rho;
  TempDir dir;
  const std::string path = dir.File("calibrated.yaml");
  ASSERT_TRUE(SaveCalibratedModel(PerturbedPuma(&rng, &rho), path).ok());
  std::string text = ReadFile(path);
  text.replace(text.find("version: 1\n"), 11, "version: 2\n");
  WriteFile(path, text);
  const Status status = LoadCalibratedModel(path).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("`version` = `2` at " + path + ":4: this selfcal reads selfcal-calibrated-model version 1.x only"),
            std::string::npos)
      << status.message();
  EXPECT_EQ(LoadRobotModel(path).status().code(), ErrorCode::kInvalidInput);
  // A minor version only adds optional keys: accepted.
  text.replace(text.find("version: 2\n"), 11, "version: 1.4\n");
  WriteFile(path, text);
  EXPECT_TRUE(LoadCalibratedModel(path).ok());
}

TEST(CalibratedModel, PlainRobotConfigIsNotACalibratedModel) {
  const std::string path = SourcePath("config/robots/puma560.yaml");
  const Status status = LoadCalibratedModel(path).status();
  EXPECT_NE(status.message().find("is a robot config, not a calibrated model"), std::string::npos) << status.message();
}

// A robot config is the manufacturer's data: the calibrated keys, the camera among them, are refused there.
TEST(CalibratedModel, ARobotConfigHoldsNoCamera) {
  TempDir dir;
  const std::string path = dir.File("robot.yaml");
  WriteFile(path, ReadFile(SourcePath("config/robots/puma560.yaml")) +
                      "camera: {width_px: 640, height_px: 480, fx_px: 1000, cx_px: 319.5, cy_px: 239.5}\n");
  const Status status = LoadRobotModel(path).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("camera"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("only in a `format: selfcal-calibrated-model` file"), std::string::npos) << status.message();
}

TEST(CalibratedModel, InvalidModelIsNotWritten) {
  std::mt19937_64 rng(7);
  Eigen::VectorXd rho;
  CalibratedModel calibrated = PerturbedPuma(&rng, &rho);
  calibrated.model.links[1].a = std::nan("");
  TempDir dir;
  const Status status = SaveCalibratedModel(calibrated, dir.File("bad.yaml"));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(dir.List().empty());
}

}  // namespace
}  // namespace selfcal::io
