// Test-only helpers shared by the identification tests: seeded random joint poses and exact
// relative-pose measurements from a "true" parameter vector.
#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>

#include "identification/identification.h"
#include "kinematics/robot_model.h"

namespace selfcal::identification::testing {

// Uniform within the joint limits, kept 5 deg away from them.
inline std::vector<Eigen::VectorXd> RandomPoses(const RobotModel& model, int count, std::mt19937* rng) {
  std::vector<Eigen::VectorXd> poses;
  for (int p = 0; p < count; ++p) {
    Eigen::VectorXd q(model.num_joints());
    for (int i = 0; i < model.num_joints(); ++i) {
      const double margin = DegToRad(5);
      std::uniform_real_distribution<double> u(model.limits[i].min_rad + margin, model.limits[i].max_rad - margin);
      q[i] = u(*rng);
    }
    poses.push_back(q);
  }
  return poses;
}

inline Rigid3 TrueRelativePose(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q_ref,
                               const Eigen::VectorXd& q_i) {
  return BaseFromCam(model, rho, q_ref).Inverse() * BaseFromCam(model, rho, q_i);
}

// One measurement per pose other than the reference, exact.
inline std::vector<RelativePoseMeasurement> ExactMeasurements(const RobotModel& model, const Eigen::VectorXd& rho,
                                                              const std::vector<Eigen::VectorXd>& poses,
                                                              int reference_index) {
  std::vector<RelativePoseMeasurement> out;
  for (int i = 0; i < static_cast<int>(poses.size()); ++i) {
    if (i == reference_index) continue;
    RelativePoseMeasurement m;
    m.pose_index = i;
    m.cam_ref_from_cam_i = TrueRelativePose(model, rho, poses[reference_index], poses[i]);
    out.push_back(m);
  }
  return out;
}

}  // namespace selfcal::identification::testing
