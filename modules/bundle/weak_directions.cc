// Weak directions of the kinematic bundle adjustment: near-unidentifiable joint parameters held at the
// robot description's value (BundleOptions::weak_length_tolerance_m, weak_angle_tolerance_rad).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

#include "bundle/weak_holding.h"

#include "bundle/bundle_problem.h"

namespace selfcal::bundle::internal {

bool FindWeakParameters(const BundleData& data, const BundleState& state, const Gauge& gauge,
                        const IntrinsicsMask& estimate, double length_tolerance_m, double angle_tolerance_rad,
                        std::vector<identification::WeakColumn>* weak) {
  weak->clear();
  const int num_joints = data.robot.num_joints();
  const KinematicParameters params(num_joints);
  GlobalColumns columns;
  columns.kinematic = gauge.free_kinematic;
  for (int k : EstimatedIntrinsics(estimate)) {
    if (gauge.intrinsics_identifiable[k]) columns.intrinsics.push_back(k);
  }
  Eigen::MatrixXd reduced;
  if (!ReducedJacobian(data, state, columns, &reduced)) return false;
  const int nk = static_cast<int>(columns.kinematic.size());
  // The gauge's order over these columns: the intrinsics, then camera, base, joint by joint, betas last.
  std::vector<int> order;
  for (int k = 0; k < static_cast<int>(columns.intrinsics.size()); ++k) order.push_back(nk + k);
  Eigen::VectorXd tolerance = Eigen::VectorXd::Zero(columns.size());
  for (int c : identification::PreferredParameterOrder(num_joints)) {
    auto it = std::find(columns.kinematic.begin(), columns.kinematic.end(), c);
    if (it == columns.kinematic.end()) continue;
    const int local = static_cast<int>(it - columns.kinematic.begin());
    order.push_back(local);
    const bool joint = c >= KinematicParameters::JointOffset(0) && c < params.CamOffset();
    if (joint) tolerance[local] = params.kind(c) == ParameterKind::kLength ? length_tolerance_m : angle_tolerance_rad;
  }
  *weak = identification::FindWeakColumns(reduced, order, tolerance, GlobalNames(columns, num_joints));
  // Back to rho indices.
  for (identification::WeakColumn& w : *weak) w.column = columns.kinematic[w.column];
  return true;
}

namespace {

// Holds `weak` at the robot description's values (the state moved there) and names them in the report.
void HoldAtNominal(const std::vector<identification::WeakColumn>& weak, bool under_error_model, const BundleData& data,
                   Gauge* gauge, BundleState* state, BundleReport* report) {
  const Eigen::VectorXd nominal_rho = KinematicParameters::Nominal(data.robot);
  const KinematicParameters params(data.robot.num_joints());
  for (const identification::WeakColumn& w : weak) {
    report->weak.push_back({params.name(w.column), params.kind(w.column) == ParameterKind::kLength,
                            w.conditional_std, w.tolerance, w.combination, under_error_model});
    report->fixed_names.push_back(params.name(w.column));
    state->rho[w.column] = nominal_rho[w.column];
    if (w.column < report->stddev.size()) report->stddev[w.column] = NAN;
    auto it = std::find(gauge->free_kinematic.begin(), gauge->free_kinematic.end(), w.column);
    if (it != gauge->free_kinematic.end()) gauge->free_kinematic.erase(it);
  }
  gauge->free_names.clear();
  for (int i : gauge->free_kinematic) gauge->free_names.push_back(params.name(i));
  report->free_indices = gauge->free_kinematic;
  report->free_names = gauge->free_names;
}

}  // namespace

bool HoldWeakAtNominal(const BundleData& data, const BundleOptions& options, Gauge* gauge, BundleState* state,
                       BundleReport* report) {
  // Judged at the nominal model, with the start's dots and intrinsics.
  BundleState nominal = *state;
  nominal.rho = KinematicParameters::Nominal(data.robot);
  std::vector<identification::WeakColumn> weak;
  if (!FindWeakParameters(data, nominal, *gauge, options.intrinsics, options.weak_length_tolerance_m,
                          options.weak_angle_tolerance_rad, &weak)) {
    return false;
  }
  HoldAtNominal(weak, false, data, gauge, state, report);
  return true;
}

// Weak directions under the cell's error model, once the fit has estimated it: the first judgement
// (HoldWeakParameters, each parameter given the ones before it, at the stated pixel noise) misses what each
// image's pose error (joint reading noise, what the model does not hold) leaves poorly determined. Of the free
// joint parameters whose standard deviation under the model exceeds their tolerance, mostly through the pose
// error (the pixel noise alone would not), the one that exceeds it by the most is held at the description's
// value and named with the free parameters it is most correlated with; true when one was (the caller refits
// and asks again).
bool HoldWeakestUnderErrorModel(const BundleData& data, const BundleOptions& options, Gauge* gauge,
                                BundleState* state, BundleReport* report) {
  // The pose part of the covariance exists only under an estimated model.
  if (!report->covariance_available || !report->error_model.estimated) return false;
  const KinematicParameters params(data.robot.num_joints());
  const std::vector<int>& free = gauge->free_kinematic;
  int worst = -1;
  double worst_ratio = 1.0, worst_tolerance = 0;
  for (size_t k = 0; k < free.size(); ++k) {
    const int c = free[k];
    if (c < KinematicParameters::JointOffset(0) || c >= params.CamOffset()) continue;
    const double tolerance =
        params.kind(c) == ParameterKind::kLength ? options.weak_length_tolerance_m : options.weak_angle_tolerance_rad;
    // Only what the pose error leaves poorly determined (most of its variance the pose error's, the pixel
    // noise's alone within the tolerance): otherwise the first judgement stands, and a pose error found by
    // chance in a pose-free cell holds nothing.
    const double pose_variance = report->covariance_pose_part(k, k);
    const double pixel_variance = report->covariance_free(k, k) - pose_variance;
    if (!(tolerance > 0) || !(report->stddev[c] > tolerance * worst_ratio) ||
        !(pixel_variance <= tolerance * tolerance) || !(pose_variance > pixel_variance)) {
      continue;
    }
    worst = static_cast<int>(k);
    worst_ratio = report->stddev[c] / tolerance;
    worst_tolerance = tolerance;
  }
  if (worst < 0) return false;
  identification::WeakColumn w;
  w.column = free[worst];
  w.conditional_std = report->stddev[w.column];
  w.tolerance = worst_tolerance;
  std::vector<std::pair<double, int>> partners;
  for (size_t k = 0; k < free.size(); ++k) {
    if (static_cast<int>(k) != worst) partners.push_back({report->correlation_free(worst, k), free[k]});
  }
  std::sort(partners.begin(), partners.end(),
            [](const auto& x, const auto& y) { return std::abs(x.first) > std::abs(y.first); });
  std::ostringstream combination;
  combination << "correlated with";
  for (size_t k = 0; k < std::min<size_t>(2, partners.size()); ++k) {
    combination << (k ? ", " : " ") << params.name(partners[k].second) << " (" << std::setprecision(2)
                << partners[k].first << ")";
  }
  w.combination = combination.str();
  HoldAtNominal({w}, true, data, gauge, state, report);
  return true;
}

}  // namespace selfcal::bundle::internal
