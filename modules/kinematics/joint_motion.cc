#include "kinematics/joint_motion.h"

#include <algorithm>
#include <cstdio>

#include "geometry/rigid3.h"

namespace selfcal {

std::vector<BarelyMovingJoint> BarelyMovingJoints(const std::vector<Eigen::VectorXd>& joints, double threshold_rad) {
  std::vector<BarelyMovingJoint> out;
  if (joints.empty()) return out;
  for (Eigen::Index j = 0; j < joints.front().size(); ++j) {
    double lo = joints.front()[j], hi = lo;
    for (const Eigen::VectorXd& q : joints) {
      if (j >= q.size()) return out;
      lo = std::min(lo, q[j]);
      hi = std::max(hi, q[j]);
    }
    if (hi - lo < threshold_rad) out.push_back({static_cast<int>(j) + 1, hi - lo});
  }
  return out;
}

std::string BarelyMovesSentence(const BarelyMovingJoint& joint, const std::string& poses) {
  char degrees[32];
  std::snprintf(degrees, sizeof(degrees), "%.1f", RadToDeg(joint.range_rad));
  return "joint " + std::to_string(joint.joint) + " barely moves (" + degrees + " deg over " + poses +
         "): the parameters beside it are hard to tell apart";
}

Eigen::Matrix<double, 6, Eigen::Dynamic> CameraMotionPerJoint(const RobotModel& robot, const Eigen::VectorXd& rho,
                                                              const Eigen::VectorXd& q) {
  constexpr double kStep = 1e-6;  // rad: the motion is linear far beyond it, the rounding far below
  const Eigen::Index n = q.size();
  Eigen::Matrix<double, 6, Eigen::Dynamic> a(6, n);
  const Rigid3 points_from_cam = PointsFromCam(robot, rho, q);
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::VectorXd plus = q, minus = q;
    plus[k] += kStep;
    minus[k] -= kStep;
    // p_cam' = cam'_from_points * points_from_cam * p_cam.
    const Rigid3 up = PointsFromCam(robot, rho, plus).Inverse() * points_from_cam;
    const Rigid3 down = PointsFromCam(robot, rho, minus).Inverse() * points_from_cam;
    a.block<3, 1>(0, k) = (up.translation - down.translation) / (2 * kStep);
    a.block<3, 1>(3, k) = (LogSO3(up.rotation) - LogSO3(down.rotation)) / (2 * kStep);
  }
  return a;
}

}  // namespace selfcal
