#include "planning/observability.h"

#include <cmath>

#include <Eigen/SVD>

#include "base/status.h"
#include "identification/identifiability.h"
#include "planning/fisher_design.h"

namespace selfcal::planning {

ObservabilityReport AnalyzeObservability(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                                         double pixel_noise_px, identification::IdentifiabilityReport* identifiability) {
  const std::string invalid = problem.Validate();
  SELFCAL_CHECK(invalid.empty(), "planning problem: " << invalid);
  SELFCAL_CHECK(pixel_noise_px > 0, "pixel noise " << pixel_noise_px << " must be > 0");
  ObservabilityReport report;
  report.pixel_noise_px = pixel_noise_px;
  const int m_id = problem.num_identification_poses;
  if (static_cast<int>(poses.size()) < m_id || m_id < 3) {
    report.message = "fewer poses than identification poses";
    return report;
  }
  for (const Eigen::VectorXd& q : poses) {
    if (q.size() != problem.robot.num_joints() || !q.allFinite()) {
      report.message = "a pose has the wrong joint count or a non-finite value";
      return report;
    }
  }
  const std::vector<Eigen::VectorXd> id_poses(poses.begin(), poses.begin() + m_id);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  const identification::IdentifiabilityOptions id_options;
  const Eigen::MatrixXd full = identification::RelativePoseJacobian(problem.robot, rho, id_poses, 0,
                                                                    id_options.sigma_position_m, id_options.sigma_rotation_rad);
  const identification::IdentifiabilityReport id =
      identification::AnalyzeIdentifiabilityOfJacobian(problem.robot, rho, full, id_poses, 0, id_options);
  if (identifiability != nullptr) *identifiability = id;
  report.free_names = id.free_names;
  report.fixed_names = id.fixed_names;
  report.free_indices = id.free_indices;
  Eigen::MatrixXd j(full.rows(), id.free_indices.size());
  for (size_t c = 0; c < id.free_indices.size(); ++c) {
    j.col(c) = full.col(id.free_indices[c]);
    j.col(c) /= j.col(c).norm();
  }
  report.rows = static_cast<int>(j.rows());
  report.columns = static_cast<int>(j.cols());
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(j).singularValues();
  report.min_singular_value = s(s.size() - 1);
  report.condition_number = s(0) / report.min_singular_value;
  report.log10_product_singular_values = s.array().log10().sum();
  report.observability_index =
      std::pow(10.0, report.log10_product_singular_values / report.columns) / std::sqrt(static_cast<double>(report.rows));
  report.noise_amplification_index = report.min_singular_value * report.min_singular_value / s(0);
  report.ok = true;

  FisherDesignOptions fisher_options;
  fisher_options.pixel_noise_px = pixel_noise_px;
  FisherDesign design(problem, id.free_indices, fisher_options);
  std::vector<int> all;
  for (const Eigen::VectorXd& q : id_poses) all.push_back(design.AddCandidate(q));
  const FisherValue v = design.Evaluate(all);
  report.prediction_ok = v.ok;
  if (v.ok) {
    report.predicted_stddev.assign(v.stddev.data(), v.stddev.data() + report.columns);
    report.predicted_fx_stddev_px = v.stddev[report.columns];
  } else {
    report.message = "the bundle adjustment's information is singular for these poses and this scene";
  }
  return report;
}

}  // namespace selfcal::planning
