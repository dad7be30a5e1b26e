#include "identification/identifiability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>

#include <Eigen/Dense>

#include "base/status.h"
#include "identification/rank_selection.h"
#include "identification/relative_pose_residual.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::identification {

namespace {

void CheckInputs(const RobotModel& model, const Eigen::VectorXd& rho, const std::vector<Eigen::VectorXd>& joint_poses,
                 int reference_index, double sigma_position_m, double sigma_rotation_rad) {
  SELFCAL_CHECK(rho.size() == model.num_parameters(),
                "rho has " << rho.size() << " entries, the model needs " << model.num_parameters());
  SELFCAL_CHECK(reference_index >= 0 && reference_index < static_cast<int>(joint_poses.size()),
                "reference index " << reference_index << " outside [0, " << joint_poses.size() << ")");
  for (size_t i = 0; i < joint_poses.size(); ++i) {
    SELFCAL_CHECK(joint_poses[i].size() == model.num_joints(), "joint pose " << i << " has " << joint_poses[i].size()
                                                                             << " angles, the robot "
                                                                             << model.num_joints());
  }
  SELFCAL_CHECK(std::isfinite(sigma_position_m) && sigma_position_m > 0, "sigma_position_m = " << sigma_position_m);
  SELFCAL_CHECK(std::isfinite(sigma_rotation_rad) && sigma_rotation_rad > 0,
                "sigma_rotation_rad = " << sigma_rotation_rad);
}

}  // namespace

Eigen::MatrixXd RelativePoseJacobian(const RobotModel& model, const Eigen::VectorXd& rho,
                                     const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                     double sigma_position_m, double sigma_rotation_rad) {
  CheckInputs(model, rho, joint_poses, reference_index, sigma_position_m, sigma_rotation_rad);
  const int num_poses = static_cast<int>(joint_poses.size());
  // Measurements equal to the model: only the derivative matters and the residual is zero.
  const Rigid3 cam_ref_from_base = internal::CamRefFromBase<double>(model, rho.data(), joint_poses[reference_index]);
  std::vector<Rigid3> measured(num_poses);
  for (int i = 0; i < num_poses; ++i) measured[i] = cam_ref_from_base * PointsFromCam(model, rho, joint_poses[i]);

  const double inv_sp = 1.0 / sigma_position_m, inv_sr = 1.0 / sigma_rotation_rad;
  auto residuals = [&](const auto* x, auto* y) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(x)>>;
    const Rigid3T<T> ref_from_base = internal::CamRefFromBase<T>(model, x, joint_poses[reference_index]);
    int row = 0;
    for (int i = 0; i < num_poses; ++i) {
      if (i == reference_index) continue;
      internal::RelativePoseResidual<T>(model, x, ref_from_base, joint_poses[i], measured[i], true, inv_sp, inv_sr,
                                        y + row);
      row += 6;
    }
  };
  return AutodiffJacobian<8>(residuals, rho, 6 * (num_poses - 1));
}

IdentifiabilityReport AnalyzeIdentifiability(const RobotModel& model, const Eigen::VectorXd& rho,
                                             const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                             const IdentifiabilityOptions& options) {
  const Eigen::MatrixXd jacobian = RelativePoseJacobian(model, rho, joint_poses, reference_index,
                                                        options.sigma_position_m, options.sigma_rotation_rad);
  return AnalyzeIdentifiabilityOfJacobian(model, rho, jacobian, joint_poses, reference_index, options);
}

IdentifiabilityReport AnalyzeIdentifiabilityOfJacobian(const RobotModel& model, const Eigen::VectorXd& rho,
                                                       const Eigen::MatrixXd& jacobian,
                                                       const std::vector<Eigen::VectorXd>& joint_poses,
                                                       int reference_index, const IdentifiabilityOptions& options) {
  SELFCAL_CHECK(std::isfinite(options.rank_tolerance) && options.rank_tolerance > 0 && options.rank_tolerance < 1,
                "rank_tolerance = " << options.rank_tolerance << " must lie in (0, 1)");
  SELFCAL_CHECK(jacobian.cols() == model.num_parameters() &&
                    jacobian.rows() == 6 * (static_cast<Eigen::Index>(joint_poses.size()) - 1),
                "the Jacobian is " << jacobian.rows() << " x " << jacobian.cols() << " for " << joint_poses.size()
                                   << " poses and " << model.num_parameters() << " parameters");
  const int n = model.num_parameters();
  const int rows = static_cast<int>(jacobian.rows());
  const KinematicParameters params(model.num_joints());

  // Column 0 is the global scale of the measured translations when it is unknown: the residual
  // (t_model - s t_meas) / sigma has derivative -t_meas / sigma at s = 1, and t_meas = t_model here.
  const int offset = options.scale_known ? 0 : 1;
  const int cols = n + offset;
  std::vector<std::string> names;
  if (!options.scale_known) names.push_back("scale");
  names.insert(names.end(), params.names().begin(), params.names().end());
  Eigen::MatrixXd full(rows, cols);
  full.rightCols(n) = jacobian;
  if (!options.scale_known) {
    full.col(0).setZero();
    const Rigid3 cam_ref_from_base = internal::CamRefFromBase<double>(model, rho.data(), joint_poses[reference_index]);
    int row = 0;
    for (int i = 0; i < static_cast<int>(joint_poses.size()); ++i) {
      if (i == reference_index) continue;
      const Rigid3 rel = cam_ref_from_base * PointsFromCam(model, rho, joint_poses[i]);
      full.col(0).segment<3>(row + 3) = -rel.translation / options.sigma_position_m;
      row += 6;
    }
  }

  // The scale (a nuisance estimated alongside) first, then the parameters in the preferred order.
  std::vector<int> order;
  if (!options.scale_known) order.push_back(0);
  for (int c : PreferredParameterOrder(model.num_joints())) order.push_back(c + offset);
  const RankSelection selection = SelectColumns(full, order, options.rank_tolerance, names);

  IdentifiabilityReport report;
  report.num_parameters = n;
  report.singular_values = selection.singular_values;
  report.condition_number = selection.condition_number;
  report.null_combinations = selection.null_combinations;
  for (int c : selection.kept) {
    if (c >= offset) report.free_indices.push_back(c - offset);
  }
  for (int c : selection.dependent) {
    if (c >= offset) report.fixed_indices.push_back(c - offset);
  }
  report.rank = static_cast<int>(report.free_indices.size());
  for (int i : report.free_indices) report.free_names.push_back(params.name(i));
  for (int i : report.fixed_indices) report.fixed_names.push_back(params.name(i));
  return report;
}

int GenericRank(const RobotModel& model, const Eigen::VectorXd& rho, double rank_tolerance) {
  std::mt19937_64 rng(20240607);
  std::vector<Eigen::VectorXd> poses;
  const int count = std::max(12, model.num_parameters() / 2);
  for (int p = 0; p < count; ++p) {
    Eigen::VectorXd q(model.num_joints());
    for (int j = 0; j < model.num_joints(); ++j) {
      std::uniform_real_distribution<double> u(model.limits[j].min_rad, model.limits[j].max_rad);
      q[j] = u(rng);
    }
    poses.push_back(q);
  }
  IdentifiabilityOptions options;
  options.rank_tolerance = rank_tolerance;
  options.scale_known = true;  // the yardstick
  return AnalyzeIdentifiability(model, rho, poses, 0, options).rank;
}

}  // namespace selfcal::identification
