#include "support/test_robots.h"

namespace selfcal::testing {

namespace {
Rigid3 CameraOnFlange() {
  // Camera looks along the flange z axis, rotated 90 deg about it, offset 40 mm in x and 60 mm in z.
  return Rigid3(RotZ(kPi / 2), Eigen::Vector3d(0.04, 0.0, 0.06));
}
}  // namespace

RobotModel Puma560() {
  const double h = kPi / 2;
  const std::vector<DhRow> rows = {
      {0.0, h, 0.0, 0.0}, {0.4318, 0.0, 0.0, 0.0}, {0.0203, -h, 0.15005, 0.0},
      {0.0, h, 0.4318, 0.0}, {0.0, -h, 0.0, 0.0},   {0.0, 0.0, 0.0, 0.0}};
  const std::vector<JointLimits> limits = {
      {DegToRad(-160), DegToRad(160)}, {DegToRad(-45), DegToRad(225)},  {DegToRad(-225), DegToRad(45)},
      {DegToRad(-110), DegToRad(170)}, {DegToRad(-100), DegToRad(100)}, {DegToRad(-266), DegToRad(266)}};
  return RobotModel::FromDh("puma560", DhConvention::kStandard, rows, limits, Rigid3(), CameraOnFlange());
}

RobotModel Ur5e() {
  const double h = kPi / 2;
  const std::vector<DhRow> rows = {
      {0.0, h, 0.1625, 0.0}, {-0.425, 0.0, 0.0, 0.0}, {-0.3922, 0.0, 0.0, 0.0},
      {0.0, h, 0.1333, 0.0}, {0.0, -h, 0.0997, 0.0},  {0.0, 0.0, 0.0996, 0.0}};
  std::vector<JointLimits> limits(6, JointLimits{DegToRad(-360), DegToRad(360)});
  limits[2] = {DegToRad(-180), DegToRad(180)};
  return RobotModel::FromDh("ur5e", DhConvention::kStandard, rows, limits, Rigid3(), CameraOnFlange());
}

::testing::AssertionResult RigidNear(const Rigid3& expected, const Rigid3& actual, double rot_tol_rad,
                                     double trans_tol_m) {
  const PoseDifference d = ComparePoses(expected, actual);
  if (d.rotation_rad > rot_tol_rad) {
    return ::testing::AssertionFailure() << "rotation differs by " << d.rotation_rad << " rad > " << rot_tol_rad;
  }
  if (d.position_m > trans_tol_m) {
    return ::testing::AssertionFailure() << "translation differs by " << d.position_m << " m > " << trans_tol_m;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace selfcal::testing
