// Module identification (ARCHITECTURE.md): identifiability (identifiability.h: rank analysis, named null
// space; rank_selection.h, shared with bundle), LM identification with covariance (this header), eq. (21)
// scale, triangulation and the yardstick scale (triangulation.h). Uses kinematics, camera, geometry, base;
// Ceres private.
//
// Kinematic identification from measured relative camera poses (paper section 2.3, eq. (6); section 4.1
// step 3): Levenberg-Marquardt (Ceres) over the identifiable parameters, started from the nominal model.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::identification {

struct RelativePoseMeasurement {
  int pose_index = -1;                 // into joint_poses
  Rigid3 cam_ref_from_cam_i;           // measured
  bool translation_valid = true;       // false: rotation only (pure rotation pair, G3)
};

struct IdentificationOptions {
  double sigma_position_m = 1e-3;      // residual weights (and the a-priori measurement std)
  double sigma_rotation_rad = 1e-4;
  int max_iterations = 200;  // the UR5e-class arm needs up to ~90 from the nominal start
  double function_tolerance = 1e-15;
  double gradient_tolerance = 1e-15;
  double parameter_tolerance = 1e-15;
  std::string Validate() const;
};

enum class Outcome {
  kNotRun,
  kConverged,      // Ceres CONVERGENCE (K4)
  kNoConvergence,  // Ceres NO_CONVERGENCE: result kept but marked unconverged, never "applied"
  kFailure,        // Ceres FAILURE / USER_FAILURE, or non-finite start (K5)
  kInvalidInput,
};
const char* OutcomeName(Outcome outcome);

struct IdentificationReport {
  Outcome outcome = Outcome::kNotRun;
  std::string message;
  Eigen::VectorXd rho;                    // full vector; fixed entries keep their start values
  std::vector<int> free_indices;
  // Per-parameter standard deviation (full size; NaN for fixed parameters or when unavailable), from
  // the covariance s^2 (J^T J)^-1 of the free parameters with s^2 = 2 final_cost / (residuals - free).
  Eigen::VectorXd stddev;
  bool covariance_available = false;
  std::string covariance_message;         // e.g. "uncertainty unavailable (rank deficient: j3.d)" (K8)
  Eigen::MatrixXd covariance_free;        // free x free
  Eigen::MatrixXd correlation_free;
  double initial_cost = 0, final_cost = 0;  // Ceres cost, 0.5 * sum of squared weighted residuals
  int iterations = 0;
  std::string termination;                // Ceres termination type and message
  // Unweighted, at the solution: RMS over measurements of |t_model - t_meas| (translation-valid ones) and
  // of the angle of R_model^T R_meas.
  double rms_position_m = 0, rms_rotation_rad = 0;
};

IdentificationReport IdentifyFromRelativePoses(const RobotModel& model, const Eigen::VectorXd& rho_start,
                                               const std::vector<int>& free_indices,
                                               const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                               const std::vector<RelativePoseMeasurement>& measurements,
                                               const IdentificationOptions& options);

}  // namespace selfcal::identification
