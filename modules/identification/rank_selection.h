// Which columns of a Jacobian carry independent information, decided greedily in a preferred order, with
// the dependent ones written as named null-space combinations (../shared/DESIGN.md section 4,
// ../shared/RELIABILITY.md K1).
// Shared by the relative-pose identifiability analysis and the kinematic bundle adjustment's gauge.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace selfcal::identification {

struct RankSelection {
  std::vector<int> kept, dependent;          // column indices, ascending
  std::vector<std::string> null_combinations;
  double condition_number = 0;               // of the kept, column-normalised columns
  Eigen::VectorXd singular_values;           // of the column-normalised matrix, descending
};
// Gram-Schmidt in `order` on the column-normalised matrix: a column is kept when its part orthogonal to
// the kept ones exceeds tolerance * (largest singular value). Columns below tolerance * (largest norm)
// count as zero (round-off of an exact gauge).
RankSelection SelectColumns(const Eigen::MatrixXd& jacobian, const std::vector<int>& order, double tolerance,
                            const std::vector<std::string>& names);

// Weak columns (near-unidentifiable directions, not only exact rank deficiency): Gram-Schmidt over
// `order` on the whitened columns (rows divided by their noise, so 1 / |part of a column orthogonal to the
// columns kept before it| is that parameter's standard deviation given them). A column with tolerance > 0
// whose conditional standard deviation exceeds its tolerance is weak: the data determine it worse than the
// tolerance the caller trusts its nominal value to (a manufacturing tolerance), so it joins no basis and is
// reported with the kept columns it trades off with. Columns with tolerance 0 are never weak.
struct WeakColumn {
  int column = -1;
  double conditional_std = 0;  // in the column's unit
  double tolerance = 0;
  std::string combination;     // "0.71 j2.d - 0.71 j4.d": the column and the earlier ones it trades off with
};
std::vector<WeakColumn> FindWeakColumns(const Eigen::MatrixXd& whitened, const std::vector<int>& order,
                                        const Eigen::VectorXd& tolerance, const std::vector<std::string>& names);

// "0.71 j2.d - 0.71 j3.d": terms above 0.05 in magnitude, by printed weight, leading sign positive.
std::string FormatCombination(const Eigen::VectorXd& v, const std::vector<std::string>& names);

// Columns scaled to unit norm (norms written to *norms); those below tolerance * (largest norm) are set
// to zero and flagged in *zero: the round-off of an exact gauge would otherwise become a fake direction.
Eigen::MatrixXd NormalizeColumns(const Eigen::MatrixXd& j, double tolerance, Eigen::VectorXd* norms,
                                 std::vector<bool>* zero);

// rho indices (KinematicParameters layout) in the order the greedy selection prefers to keep them:
// camera correction, base, then alpha, a, theta, d joint by joint, the Hayati betas last.
std::vector<int> PreferredParameterOrder(int num_joints);

}  // namespace selfcal::identification
