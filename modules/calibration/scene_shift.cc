#include "calibration/scene_shift.h"

#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "base/numbers.h"
#include "geometry/rigid3.h"
#include "kinematics/damped_least_squares.h"

namespace selfcal::calibration {
namespace {

// The dots' residuals (px) with the points moved by x = (translation, rotation vector about `centre`); a dot
// that does not project (behind the camera) counts 0 and is reported in *lost.
Eigen::VectorXd ShiftResiduals(const std::vector<ShiftDot>& dots, const CameraIntrinsics& camera,
                               const Eigen::Vector3d& centre, const Eigen::Matrix<double, 6, 1>& x, int* lost) {
  const Eigen::Matrix3d r = ExpSO3<double>(x.tail<3>());
  Eigen::VectorXd residuals = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(dots.size()));
  *lost = 0;
  for (std::size_t i = 0; i < dots.size(); ++i) {
    const Eigen::Vector3d moved = r * (dots[i].point - centre) + centre + x.head<3>();
    const std::optional<Eigen::Vector2d> uv = Project(camera, dots[i].cam_from_points * moved);
    if (!uv) {
      ++*lost;
      continue;
    }
    residuals.segment<2>(2 * static_cast<Eigen::Index>(i)) = *uv - dots[i].pixel;
  }
  return residuals;
}

double RmsPerCoordinate(const Eigen::VectorXd& r) { return r.size() ? std::sqrt(r.squaredNorm() / r.size()) : 0.0; }

}  // namespace

std::vector<ShiftDot> ShiftDotsOf(const ObservationSet& obs, const std::vector<int>& pose_indices,
                                  const RobotModel& robot, const Eigen::VectorXd& rho,
                                  const std::map<int, Eigen::Vector3d>& points, int* poses_seen) {
  std::vector<ShiftDot> dots;
  if (poses_seen != nullptr) *poses_seen = 0;
  for (const int index : pose_indices) {
    const PoseObservation& pose = obs.poses[static_cast<std::size_t>(index)];
    const Rigid3 cam_from_points = PointsFromCamAt(robot, rho, pose).Inverse();
    const std::size_t before = dots.size();
    for (const auto& [id, pixel] : pose.dots_px) {
      const auto point = points.find(id);
      if (point != points.end()) dots.push_back({cam_from_points, point->second, pixel});
    }
    if (poses_seen != nullptr && dots.size() > before) ++*poses_seen;
  }
  return dots;
}

double MeanSquareAfter(const std::vector<ShiftDot>& dots, const CameraIntrinsics& camera, const SceneShift& shift,
                       double lost_px) {
  if (dots.empty()) return 0;
  int lost = 0;
  const Eigen::VectorXd r = ShiftResiduals(dots, camera, shift.centre, shift.move, &lost);
  return (r.squaredNorm() + 2.0 * lost * lost_px * lost_px) / static_cast<double>(r.size());
}

SceneShift SceneShiftOfPoses(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                             const Eigen::VectorXd& rho, const CameraIntrinsics& camera,
                             const std::map<int, Eigen::Vector3d>& points) {
  int poses = 0;
  SceneShift shift = SceneShiftOfDots(ShiftDotsOf(obs, pose_indices, robot, rho, points, &poses), camera);
  shift.poses = poses;
  return shift;
}

SceneShift SceneShiftOfDots(const std::vector<ShiftDot>& dots, const CameraIntrinsics& camera) {
  SceneShift shift;
  shift.dots = static_cast<int>(dots.size());
  if (dots.size() < 3) return shift;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const ShiftDot& dot : dots) centre += dot.point;
  centre /= static_cast<double>(dots.size());
  int lost = 0;
  const Eigen::VectorXd before = ShiftResiduals(dots, camera, centre, Eigen::Matrix<double, 6, 1>::Zero(), &lost);
  if (lost > 0) return shift;
  shift.rms_before_px = RmsPerCoordinate(before);
  // A dot that stops projecting makes a step worse than any (kLostPx), so the solver never takes it; one lost
  // in a Jacobian's central difference spoils that Jacobian, and the solve gives no figure.
  constexpr double kLostPx = 1e6;
  bool jacobian_lost = false;
  const ResidualAndJacobian evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* j) {
    int lost_here = 0;
    *r = ShiftResiduals(dots, camera, centre, x, &lost_here);
    if (lost_here > 0) r->setConstant(kLostPx);
    j->resize(r->size(), 6);
    for (int k = 0; k < 6; ++k) {  // central differences: 1 um, 1 urad
      Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();
      step[k] = 1e-6;
      int lost_plus = 0, lost_minus = 0;
      j->col(k) = (ShiftResiduals(dots, camera, centre, x + step, &lost_plus) -
                   ShiftResiduals(dots, camera, centre, x - step, &lost_minus)) / 2e-6;
      if (lost_here == 0 && lost_plus + lost_minus > 0) jacobian_lost = true;
    }
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  MinimiseDampedLeastSquares(evaluate, &x, 50);
  if (jacobian_lost) return shift;
  const Eigen::VectorXd r = ShiftResiduals(dots, camera, centre, x, &lost);
  if (lost > 0) return shift;
  shift.computed = true;
  shift.rms_after_px = RmsPerCoordinate(r);
  shift.translation_m = x.head<3>().norm();
  shift.rotation_rad = x.tail<3>().norm();
  shift.centre = centre;
  shift.move = x;
  return shift;
}

SceneShift SceneShiftOfVerification(const ObservationSet& obs, const RobotModel& robot, const Eigen::VectorXd& rho,
                                    const CameraIntrinsics& camera, const std::map<int, Eigen::Vector3d>& points) {
  std::vector<int> verification;
  for (std::size_t i = 0; i < obs.poses.size(); ++i) {
    if (obs.poses[i].role == PoseRole::kVerification) verification.push_back(static_cast<int>(i));
  }
  return SceneShiftOfPoses(obs, verification, robot, rho, camera, points);
}

Eigen::Vector3d SceneShift::Moved(const Eigen::Vector3d& point) const {
  return ExpSO3<double>(Eigen::Vector3d(move.tail<3>())) * (point - centre) + centre + move.head<3>();
}

bool VerificationSceneMoved(const SceneShift& shift, double chi_square, double chi_square_limit) {
  if (!shift.computed || !(shift.rms_before_px > 0)) return false;
  const double ratio = shift.rms_after_px / shift.rms_before_px;
  return ratio * 3 <= 1 && chi_square * ratio * ratio <= chi_square_limit &&
         (shift.translation_m >= 0.5e-3 || shift.rotation_rad >= 0.05 * kPi / 180);
}

}  // namespace selfcal::calibration
