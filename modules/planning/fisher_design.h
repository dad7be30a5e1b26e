// Design criteria from the Fisher information of the kinematic bundle adjustment (bundle/bundle_adjustment.h):
// how well a set of identification poses determines the identifiable kinematic parameters and f_x when
// every dot is an unknown (marginalised) and the yardstick fixes the scale.
//
// Per pose c and dot j (pinhole at the nominal f_x; k1 is not modelled here), the reprojection derivative
// with respect to parameter k is d pi / d P * (-R_c^T (omega_k x X_j + v_k)) (spatial twists,
// planning/pose_twists.h) and with respect to the dot R_c^T. The information of the global unknowns
// (free rho, f_x, and the two yardstick dots, which the stiff length term couples) is
//   H = sum_c sum_j A_cj^T A_cj + yardstick - sum_j H_gj H_jj^-1 H_gj^T          (dots j >= 2 eliminated)
// in units of 1 / sigma_px^2; the covariance of (free rho, f_x) is sigma_px^2 times the top-left block of
// H^-1, the inverse of the Schur complement of the yardstick block. Contributions are cached per candidate
// pose and summed per design (Sums); a design that differs from summed ones by one pose (the exchange)
// costs O(dots * (free + 1)^2), the dots' rank update done by planning/exchange_kernels.h: ~13 us CPU for 80 dots,
// 25 unknowns (bench/core_bench.cc BM_FisherExchange...).
//
// Criteria: D = log det of the (free rho, f_x) information (maximised; unit-free up to a constant),
// A = sum over (free rho, f_x) of variance / prior variance (minimised; priors 1 mm, 0.2 deg, 10 px by
// default: the spread of the hidden errors the simulator draws).
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "planning/plan_problem.h"

namespace selfcal::planning {

struct FisherDesignOptions {
  double pixel_noise_px = 0.2;      // scales the predicted standard deviations
  double yardstick_sigma_m = 1e-5;  // dots 0 and 1 of the scene are the yardstick's ends
  double prior_length_m = 1e-3;     // A-criterion weights
  double prior_angle_rad = DegToRad(0.2);
  double prior_fx_px = 10.0;
};

struct FisherValue {
  bool ok = false;                  // information positive definite
  double log_det = -std::numeric_limits<double>::infinity();
  double a_value = std::numeric_limits<double>::infinity();
  Eigen::VectorXd stddev;           // predicted std: free rho (m, rad) in free_columns order, then f_x (px)
};

class FisherDesign {
 public:
  FisherDesign(const PlanningProblem& problem, const std::vector<int>& free_columns, const FisherDesignOptions& options);

  // Caches the contribution of one pose; returns its index.
  int AddCandidate(const Eigen::VectorXd& q);
  int num_candidates() const { return static_cast<int>(candidates_.size()); }

  FisherValue Evaluate(const std::vector<int>& design) const;

  // The contributions of a set of poses, summed.
  struct Sums {
    Eigen::MatrixXd h_gg;               // global x global, summed over dots
    std::vector<Eigen::Matrix3d> h_jj;  // per eliminated dot
    Eigen::MatrixXd h_gj;               // (free + f_x) x 3 per eliminated dot, side by side (yardstick rows are 0)
  };
  Sums Sum(const std::vector<int>& design, int skip_position = -1) const;  // without design[skip_position]
  Sums ZeroSums() const;  // every block zero, sized for this problem
  // The design of `sums` plus candidate `extra` (-1: none). with_variances false: only ok and log_det.
  FisherValue EvaluateSums(const Sums& sums, int extra, bool with_variances) const;

  // The unit of the exchange: every pose of a design but one (Sum with a skip), with its dots eliminated once.
  // A candidate's pixel rows then update the rest's (free rho, f_x) information by a rank-two term per dot
  // (the information of new measurements with the dots marginalised under the rest's information on them),
  // instead of every dot's 3 x 3 block being factored and eliminated again. Used when the rest determines
  // every dot (each block passes the test of a dot seen from two poses); otherwise EvaluateWithRest
  // evaluates sums plus the candidate as EvaluateSums does.
  struct Rest {
    Sums sums;
    bool every_dot_determined = false;
    Eigen::MatrixXd s;                 // (free, f_x) information, dots eliminated, yardstick not yet (lower)
    std::vector<Eigen::Matrix3d> k;    // per eliminated dot: the inverse of its 3 x 3 block
    Eigen::MatrixXd p;                 // (free + f_x) x 3 per eliminated dot: k times the block's transpose
  };
  Rest PrepareRest(Sums sums) const;
  // The same value as EvaluateSums(rest.sums, extra, with_variances), to round-off.
  FisherValue EvaluateWithRest(const Rest& rest, int extra, bool with_variances) const;

 private:
  // A pose, compactly (the exchange keeps a few hundred): its camera's rotation (transposed), the twists of
  // the free parameters in the camera frame and f_x (zt: (free + f_x) x 7), every dot in the camera frame and
  // whether it is seen; the 7 x 7 sum of its dots' f^T f (DotRows) and the yardstick dots' rows of its
  // information (6 x global). A dot's pixel rows are made again from these where needed.
  struct Candidate {
    Eigen::Matrix3d rt;
    Eigen::MatrixXd zt;
    std::vector<Eigen::Vector3d> p;
    std::vector<char> seen;
    Eigen::Matrix<double, 7, 7> ff;
    Eigen::Matrix<double, 6, Eigen::Dynamic> yard;
  };
  // Dot j's pixel rows: f with respect to (camera twist in the camera frame, f_x), b with respect to the dot.
  void DotRows(const Candidate& c, int j, Eigen::Matrix<double, 2, 7>* f, Eigen::Matrix<double, 2, 3>* b) const;
  // h += the candidate's information on the globals (global x global, both triangles).
  void AddInformation(const Candidate& c, Eigen::MatrixXd* h) const;
  // Lower triangle of *s -= sum over the eliminated dots of h_gj h_jj^-1 h_gj^T, for sums plus add (may be null).
  void SubtractDots(const Sums& sums, const Candidate* add, Eigen::MatrixXd* s) const;
  // The value from s (lower, dots eliminated) and the yardstick dots' blocks: h_gy (free + f_x) x 6 and h_yy.
  FisherValue Finish(const Eigen::Ref<const Eigen::MatrixXd>& h_gy, const Eigen::Matrix<double, 6, 6>& h_yy,
                     bool with_variances, Eigen::MatrixXd* s) const;
  // The yardstick's term in the information of its two dots' coordinates.
  Eigen::Matrix<double, 6, 6> YardstickInformation() const;
  PlanningProblem problem_;
  std::vector<int> free_columns_;
  FisherDesignOptions options_;
  int num_global_ = 0;  // free + f_x + 6 yardstick coordinates
  std::vector<Candidate> candidates_;
};

}  // namespace selfcal::planning
