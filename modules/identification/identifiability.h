// Which kinematic parameters the measurements can see (../shared/DESIGN.md section 4, ../shared/RELIABILITY.md K1).
//
// The measurement of pose i is cam_ref_from_cam_i = base_from_cam(q_ref)^-1 * base_from_cam(q_i), so the
// base transform cancels, and more. Rather than assume, the rank of the stacked identification Jacobian at
// the given model and poses decides: columns are normalised, then taken greedily (scale, camera, base,
// alpha/a/theta/d joint by joint, betas last; see identifiability.cc), each kept only if it adds rank
// (relative tolerance). The rest are fixed at their start values, and the null space of the full
// Jacobian is reported as named combinations.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"

namespace selfcal::identification {

// Stacked Jacobian (6 rows per pose i != reference_index) of the relative-pose residual
//   r_i = [ (log(R_model^T R_meas)) / sigma_rotation ; (t_model - t_meas) / sigma_position ]
// of cam_ref_from_cam_i with respect to rho, at measurements equal to the model (so only the derivative
// matters). Units per row: rad / sigma_rotation_rad and m / sigma_position_m.
Eigen::MatrixXd RelativePoseJacobian(const RobotModel& model, const Eigen::VectorXd& rho,
                                     const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                     double sigma_position_m, double sigma_rotation_rad);

struct IdentifiabilityOptions {
  double rank_tolerance = 1e-8;  // relative to the largest singular value of the column-normalised J
  // false: the measured translations carry one unknown global scale (images alone); a scale column is
  // appended and its dependence reported as one more unidentifiable direction.
  bool scale_known = true;
  double sigma_position_m = 1e-3;
  double sigma_rotation_rad = 1e-4;
};

struct IdentifiabilityReport {
  int num_parameters = 0;
  int rank = 0;                            // = free_indices.size()
  std::vector<int> free_indices;           // identifiable parameters, in rho order
  std::vector<int> fixed_indices;          // fixed at their start values
  std::vector<std::string> free_names, fixed_names;
  // Null-space directions of the column-normalised Jacobian, each as "0.71 j2.d - 0.71 j3.d" (terms
  // above 0.05 in magnitude), including "scale" when !scale_known.
  std::vector<std::string> null_combinations;
  Eigen::VectorXd singular_values;         // of the column-normalised full Jacobian, descending
  double condition_number = 0;             // column-normalised Jacobian of the free parameters (+ scale)
};

IdentifiabilityReport AnalyzeIdentifiability(const RobotModel& model, const Eigen::VectorXd& rho,
                                             const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                             const IdentifiabilityOptions& options);
// The same report from the Jacobian RelativePoseJacobian gave for these poses with options' sigmas (for a
// caller that needs the Jacobian too: it is computed once).
IdentifiabilityReport AnalyzeIdentifiabilityOfJacobian(const RobotModel& model, const Eigen::VectorXd& rho,
                                                       const Eigen::MatrixXd& jacobian,
                                                       const std::vector<Eigen::VectorXd>& joint_poses,
                                                       int reference_index, const IdentifiabilityOptions& options);

// Number of identifiable parameters (metric relative poses, scale known) at 5n + 12 / 2 (at least 12)
// random joint configurations within the limits (fixed seed): what generic poses of this robot identify.
// A plan that identifies fewer does not excite some joint (K3, ../shared/RELIABILITY.md C7).
int GenericRank(const RobotModel& model, const Eigen::VectorXd& rho, double rank_tolerance);

}  // namespace selfcal::identification
