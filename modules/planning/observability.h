// Observability report of a plan (issue 4 item 3): how well its identification poses determine the
// kinematic parameters, before the robot moves.
//
// Indices (Hollerbach and Lokhorst 1995; the paper's section 3.3) on the identification Jacobian J of the
// relative poses (identification/identifiability.h: rows whitened by 1 mm and 1e-4 rad, identifiable
// columns only, each scaled to unit norm so that units do not decide), L = number of columns, r = rows:
//   condition number sigma_max / sigma_min (Borm and Menq; the paper's Cond(J) in eq. (39) is the SI one),
//   minimum singular value (Nahvi et al.),
//   product of singular values (log10) and the observability index (prod sigma)^(1/L) / sqrt(r) (Borm and Menq),
//   noise amplification index sigma_min^2 / sigma_max (Nahvi and Hollerbach 1996).
// And the predicted standard deviation of every identifiable parameter and f_x at a pixel noise: the
// Cramer-Rao bound of the kinematic bundle adjustment with the scene's dots unknown (planning/fisher_design.h).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "identification/identifiability.h"
#include "planning/plan_problem.h"

namespace selfcal::planning {

struct ObservabilityReport {
  bool ok = false;
  std::string message;
  int rows = 0, columns = 0;
  double condition_number = 0;
  double min_singular_value = 0;
  double log10_product_singular_values = 0;
  double observability_index = 0;
  double noise_amplification_index = 0;
  std::vector<std::string> free_names, fixed_names;
  std::vector<int> free_indices;
  double pixel_noise_px = 0;
  bool prediction_ok = false;
  std::vector<double> predicted_stddev;  // free parameters, SI (m, rad), in free_indices order
  double predicted_fx_stddev_px = 0;
};

// `identifiability` (optional): the identifiability analysis of the identification poses the report was made
// from (default IdentifiabilityOptions, nominal rho; left as is when the poses are refused before it).
ObservabilityReport AnalyzeObservability(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                                         double pixel_noise_px,
                                         identification::IdentifiabilityReport* identifiability = nullptr);

}  // namespace selfcal::planning
