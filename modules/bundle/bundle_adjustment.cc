#include "bundle/bundle_adjustment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <utility>

#include <Eigen/Dense>

#include "bundle/bundle_problem.h"
#include "bundle/kinematic_lm.h"
#include "bundle/weak_holding.h"
#include "identification/identifiability.h"
#include "identification/triangulation.h"
#include "kinematics/joint_motion.h"

namespace selfcal::bundle {

using internal::BundleData;
using internal::BundleState;

namespace {

using Clock = std::chrono::steady_clock;

// One Levenberg-Marquardt solve of the current problem in place (kinematic_lm.h), robust (Huber) or not.
internal::LmSummary Solve(const BundleData& data, const std::vector<int>& free, const BundleOptions& options,
                          bool robust, BundleState* state) {
  internal::LmOptions lm;
  lm.max_iterations = options.max_iterations;
  lm.function_tolerance = options.function_tolerance;
  lm.gradient_tolerance = options.gradient_tolerance;
  lm.parameter_tolerance = options.parameter_tolerance;
  lm.huber_threshold = robust ? options.huber_px / data.sigma_px : 0.0;
  return internal::SolveKinematicBundle(data, free, EstimatedIntrinsics(options.intrinsics), lm, state);
}

// |r| in pixels per observation at `state` (NaN where it cannot be evaluated).
std::vector<double> ReprojectionErrors(const BundleData& data, const BundleState& state) {
  std::vector<internal::PoseCache> caches(data.joints.size());
  for (size_t p = 0; p < data.joints.size(); ++p) {
    internal::ComputePoseCache(data, static_cast<int>(p), state.rho.data(), {}, false, &caches[p]);
  }
  std::vector<double> errors;
  for (const internal::Observation& o : data.observations) {
    double r[2];
    const bool ok = internal::EvaluateReprojection(state.intrinsics, 1.0, caches[o.pose], state.dots[o.dot], o.pixel, r,
                                                   nullptr, nullptr, nullptr);
    errors.push_back(ok ? std::hypot(r[0], r[1]) : std::numeric_limits<double>::quiet_NaN());
  }
  return errors;
}

// The observations flagged in `keep`, the dots left with two or more views (renumbered; dot_map[c] is
// the index in `full` of dot c) and the yardsticks with both ends among them.
void Subset(const BundleData& full, const BundleState& full_state, const std::vector<bool>& keep, BundleData* data,
            BundleState* state, std::vector<int>* dot_map) {
  std::vector<int> views(full.dot_ids.size(), 0);
  for (size_t k = 0; k < keep.size(); ++k) views[full.observations[k].dot] += keep[k] ? 1 : 0;
  std::vector<int> new_index(full.dot_ids.size(), -1);
  *data = full;
  data->dot_ids.clear();
  data->observations.clear();
  data->yardsticks.clear();
  *state = full_state;
  state->dots.clear();
  dot_map->clear();
  for (size_t d = 0; d < full.dot_ids.size(); ++d) {
    if (views[d] < 2) continue;
    new_index[d] = static_cast<int>(data->dot_ids.size());
    data->dot_ids.push_back(full.dot_ids[d]);
    state->dots.push_back(full_state.dots[d]);
    dot_map->push_back(static_cast<int>(d));
  }
  for (size_t k = 0; k < keep.size(); ++k) {
    internal::Observation o = full.observations[k];
    if (!keep[k] || new_index[o.dot] < 0) continue;
    o.dot = new_index[o.dot];
    data->observations.push_back(o);
  }
  for (internal::Yardstick y : full.yardsticks) {
    if (new_index[y.dot_a] < 0 || new_index[y.dot_b] < 0) continue;
    y.dot_a = new_index[y.dot_a];
    y.dot_b = new_index[y.dot_b];
    data->yardsticks.push_back(y);
  }
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& s : names) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// Every problem with the caller's input, one per line; empty when usable.
std::string CheckInputs(const ObservationSet& observations, const Eigen::VectorXd& rho_start, double fx_start,
                        const BundleOptions& options) {
  std::ostringstream problems;
  problems << options.Validate() << observations.Validate();
  if (rho_start.size() != observations.robot.num_parameters()) {
    problems << "rho_start has " << rho_start.size() << " entries, the robot needs "
             << observations.robot.num_parameters() << "\n";
  } else if (!rho_start.allFinite()) {
    problems << "rho_start is not finite\n";
  }
  if (!std::isfinite(fx_start) || fx_start <= 0) problems << "fx_start = " << fx_start << " must be finite and > 0\n";
  return problems.str();
}

// Ids of the dots seen in fewer than two identification poses: they cannot be triangulated.
std::vector<int> DotsSeenOnce(const ObservationSet& observations) {
  std::map<int, int> views;
  for (int p : observations.PosesWithRole(PoseRole::kIdentification)) {
    for (const auto& entry : observations.poses[p].dots_px) ++views[entry.first];
  }
  std::vector<int> once;
  for (const auto& [dot, count] : views) {
    if (count < 2) once.push_back(dot);
  }
  return once;
}

// Dots from the start model; a dot that cannot be triangulated there (behind a camera, no parallax)
// is dropped: its id is appended to `dropped`, it and its observations leave `data` and `state`.
void TriangulateStartDots(const Eigen::VectorXd& rho_start, BundleData* data, BundleState* state,
                          std::vector<int>* dropped) {
  std::vector<Rigid3> base_from_cam;
  for (size_t p = 0; p < data->joints.size(); ++p) {
    base_from_cam.push_back(internal::PointsFromCamOfPose(*data, static_cast<int>(p), rho_start));
  }
  std::vector<identification::PointTrack> tracks(data->dot_ids.size());
  for (const internal::Observation& o : data->observations) {
    tracks[o.dot].base_from_cam.push_back(base_from_cam[o.pose]);
    tracks[o.dot].pixels.push_back(o.pixel);
  }
  state->dots.resize(data->dot_ids.size());
  std::vector<bool> ok(data->dot_ids.size());
  for (size_t d = 0; d < tracks.size(); ++d) {
    const identification::TriangulationResult t =
        identification::TriangulatePoint(WithIntrinsics(data->camera, state->intrinsics), state->intrinsics[kFx],
                                         tracks[d], data->sigma_px);
    ok[d] = t.ok && t.point.allFinite();
    state->dots[d] = t.point;
    if (!ok[d]) dropped->push_back(data->dot_ids[d]);
  }
  std::vector<bool> keep(data->observations.size());
  for (size_t k = 0; k < keep.size(); ++k) keep[k] = ok[data->observations[k].dot];
  const BundleData all = *data;
  const BundleState all_state = *state;
  std::vector<int> dot_map;
  Subset(all, all_state, keep, data, state, &dot_map);
}

// The rho indices held by request, and the intrinsics estimated after the names (EstimatedIntrinsicsOf).
// Returns the unknown names, one per line.
std::string HeldParameters(int num_joints, BundleOptions* options, std::vector<int>* held) {
  std::string problems;
  *held = HeldParameterIndices(*options, num_joints, &problems);
  options->intrinsics = EstimatedIntrinsicsOf(*options, num_joints);
  if (!held->empty()) options->require_generic_rank = false;
  return problems;
}

// K1: the gauge and the free set, from the rank of this problem's reduced Jacobian, copied into the
// report. Evaluated at the nominal model, where nominally parallel axes are exactly parallel: at a
// perturbed start the d offsets of a parallel pair look independent (rank is a tolerance game there) and
// would run off to tens of metres (K2). False when the start model puts a dot behind a camera (K5).
bool AnalyzeStartGauge(const BundleData& data, const BundleState& state, const BundleOptions& options,
                       const std::vector<int>& held, internal::Gauge* gauge, BundleReport* report) {
  BundleState nominal = state;
  nominal.rho = KinematicParameters::Nominal(data.robot);
  if (!internal::AnalyzeGauge(data, nominal, options.intrinsics, options.rank_tolerance, gauge, held) &&
      !internal::AnalyzeGauge(data, state, options.intrinsics, options.rank_tolerance, gauge, held)) {
    return false;
  }
  report->free_indices = gauge->free_kinematic;
  report->free_names = gauge->free_names;
  report->fixed_names = gauge->fixed_names;
  report->fixed_names.insert(report->fixed_names.end(), gauge->held_names.begin(), gauge->held_names.end());
  report->held_names = gauge->held_names;
  report->null_combinations = gauge->null_combinations;
  report->condition_number = gauge->condition_number;
  // A flange-pose set has no kinematics: what generic motions identify is the hand-eye transform. Eye-to-hand
  // the chain is seen from the other end (the camera correction absorbs the base and joint 1, the points the
  // tail, as the points and the camera correction do eye-in-hand): the relative-pose analysis of the
  // eye-in-hand chain counts the same rank (bundle tests compare the two for PUMA, UR5e and Panda).
  RobotModel in_hand = data.robot;
  in_hand.mount = CameraMount::kEyeInHand;
  report->generic_rank = !data.base_from_flange.empty()
                             ? 6
                             : identification::GenericRank(in_hand, KinematicParameters::Nominal(in_hand),
                                                           options.rank_tolerance);
  return true;
}

// Weak directions: the joint parameters these poses determine worse than their manufacturing tolerance are
// held at the robot description's value (the start moved back there) and named, with the joints that barely
// move. False when the nominal model cannot be evaluated (a dot behind a camera).
bool HoldWeakParameters(const BundleData& data, const BundleOptions& options, internal::Gauge* gauge,
                        BundleState* state, BundleReport* report) {
  if (data.base_from_flange.empty()) report->barely_moving = BarelyMovingJoints(data.joints);
  if (options.weak_length_tolerance_m <= 0 && options.weak_angle_tolerance_rad <= 0) return true;
  return internal::HoldWeakAtNominal(data, options, gauge, state, report);
}

// Why the free set cannot be estimated from these poses (K3), or empty when it can.
std::string WhyNotIdentifiable(const internal::Gauge& gauge, const BundleOptions& options, int num_poses,
                               int generic_rank) {
  // In Intrinsic order, so that f_x is named first when it fails.
  for (int k : EstimatedIntrinsics(options.intrinsics)) {
    if (gauge.intrinsics_identifiable[k]) continue;
    return std::string(k == kFx ? "f_x" : IntrinsicName(k)) + " is not identifiable from these poses (null directions: " +
           Join(gauge.null_combinations) + "): hold it, or add poses that separate it";
  }
  // Every kinematic (or hand-eye) parameter held by request: nothing kinematic is left to identify, and
  // that is the request, not too little motion. The intrinsics asked for are estimated on the held model.
  if (gauge.free_kinematic.empty() && gauge.fixed_names.empty()) return "";
  if (gauge.free_kinematic.empty() ||
      (options.require_generic_rank && static_cast<int>(gauge.free_kinematic.size()) < generic_rank)) {
    std::ostringstream msg;
    msg << "insufficient excitation: these " << num_poses << " identification poses identify "
        << gauge.free_kinematic.size() << " kinematic parameters, generic poses of this robot " << generic_rank
        << "; fixed here: " << Join(gauge.fixed_names);
    return msg.str();
  }
  return "";
}

// The screen's verdict per observation: kept when |r| is within screen_sigma robust standard deviations
// (never tighter than the pixel noise). NaN is removed too.
std::vector<bool> ScreenObservations(const std::vector<double>& errors, double sigma_px, const BundleOptions& options) {
  std::vector<double> sorted;
  for (double e : errors) {
    if (std::isfinite(e)) sorted.push_back(e);
  }
  std::sort(sorted.begin(), sorted.end());
  // Median of a 2-D Gaussian's norm: sigma sqrt(2 ln 2).
  const double robust_sigma = sorted.empty() ? 0.0 : sorted[sorted.size() / 2] / std::sqrt(2.0 * std::log(2.0));
  const double threshold = options.screen_sigma * std::max(sigma_px, robust_sigma);
  std::vector<bool> keep(errors.size());
  for (size_t k = 0; k < errors.size(); ++k) keep[k] = errors[k] <= threshold;
  return keep;
}

// The globals and the subset's dots of `state` into `full_state` (dot c of the subset is dot_map[c]).
void WriteBack(const BundleState& state, const std::vector<int>& dot_map, BundleState* full_state) {
  full_state->rho = state.rho;
  full_state->intrinsics = state.intrinsics;
  for (size_t c = 0; c < dot_map.size(); ++c) full_state->dots[dot_map[c]] = state.dots[c];
}

// The observations the screen left out (keep false), each with its residual at `state`, into the report.
void ReportRemoved(const BundleData& full, const BundleState& state, const std::vector<bool>& keep, BundleReport* report) {
  const std::vector<double> errors = ReprojectionErrors(full, state);
  for (size_t k = 0; k < keep.size(); ++k) {
    if (keep[k]) continue;
    const internal::Observation& o = full.observations[k];
    report->removed.push_back({full.pose_ids[o.pose], full.dot_ids[o.dot], errors[k]});
  }
}

struct ScreenedFit {
  bool scale_lost = false;  // the screen removed the yardstick's views (S1)
  internal::LmSummary summary;  // of the final solve
};

// Robust solve, screen, refit (K7). Every round judges every observation against the current solution,
// so one wrongly removed early (while outliers still pulled the fit) comes back. On entry `data` and
// `state` are the whole problem at the start, on return the subset of the final fit and its solution.
// Adds the iterations, the initial cost, the removed observations and the dots left out to the report.
ScreenedFit SolveScreened(const std::vector<int>& free, const BundleOptions& options, BundleData* data,
                          BundleState* state, BundleReport* report) {
  ScreenedFit fit;
  const BundleData full = *data;
  BundleState full_state = *state;
  std::vector<bool> keep(full.observations.size(), true);
  std::vector<int> dot_map;
  internal::LmSummary& summary = fit.summary;
  for (int round = 0;; ++round) {
    Subset(full, full_state, keep, data, state, &dot_map);
    if (data->yardsticks.empty() && data->base_from_flange.empty()) {
      fit.scale_lost = true;
      ReportRemoved(full, full_state, keep, report);
      return fit;
    }
    summary = Solve(*data, free, options, true, state);
    if (round == 0) report->initial_cost = summary.initial_cost;
    report->iterations += summary.iterations;
    if (summary.termination == internal::LmSummary::Termination::kFailure) break;
    WriteBack(*state, dot_map, &full_state);
    if (round == options.max_screen_rounds) break;
    std::vector<bool> next = ScreenObservations(ReprojectionErrors(full, full_state), data->sigma_px, options);
    if (next == keep) break;
    keep = std::move(next);
  }
  // The final fit is plain least squares unless the Huber loss was inactive at the robust solution.
  if (summary.termination != internal::LmSummary::Termination::kFailure) {
    const std::vector<double> errors = ReprojectionErrors(*data, *state);
    if (!errors.empty() && *std::max_element(errors.begin(), errors.end()) > options.huber_px) {
      summary = Solve(*data, free, options, false, state);
      report->iterations += summary.iterations;
      WriteBack(*state, dot_map, &full_state);
    }
  }
  ReportRemoved(full, full_state, keep, report);
  std::vector<bool> in_solve(full.dot_ids.size(), false);
  for (int d : dot_map) in_solve[d] = true;
  for (size_t d = 0; d < full.dot_ids.size(); ++d) {
    if (!in_solve[d]) report->dropped_dots.push_back(full.dot_ids[d]);
  }
  return fit;
}

// The solution of a fit and its figures, into the report.
void RecordSolution(const BundleData& data, const BundleState& state, BundleReport* report) {
  report->rho = state.rho;
  report->intrinsics = state.intrinsics;
  report->fx_px = state.intrinsics[kFx];
  report->dots_in_base.clear();
  for (size_t d = 0; d < data.dot_ids.size(); ++d) report->dots_in_base[data.dot_ids[d]] = state.dots[d];
  report->num_observations = static_cast<int>(data.observations.size());
  double sum2 = 0;
  for (double e : ReprojectionErrors(data, state)) sum2 += e * e;
  report->rms_reprojection_px = report->num_observations > 0 ? std::sqrt(sum2 / report->num_observations) : 0.0;
}

// A joint set's CameraMotionPerJoint of every identification pose at `state`, the joint component's shape
// (error_model.h); empty for a flange-pose set.
std::vector<Eigen::MatrixXd> JointMotions(const BundleData& data, const BundleState& state) {
  std::vector<Eigen::MatrixXd> motions;
  if (!data.base_from_flange.empty() || data.robot.num_joints() == 0) return motions;
  for (const Eigen::VectorXd& q : data.joints) motions.push_back(CameraMotionPerJoint(data.robot, state.rho, q));
  return motions;
}

// Covariance of the free globals at the solution, dots as nuisance (K8), scaled by the residual
// variance 2 cost / dof; the standard deviations and correlations from it.
void EstimateCovariance(const BundleData& data, const BundleState& state, const std::vector<int>& free,
                        const BundleOptions& options, double final_cost, BundleReport* report) {
  internal::GlobalColumns columns;
  columns.kinematic = free;
  columns.intrinsics = EstimatedIntrinsics(options.intrinsics);
  const int num_unknowns = columns.size() + 3 * static_cast<int>(data.dot_ids.size());
  const int dof = 2 * report->num_observations + static_cast<int>(data.yardsticks.size()) - num_unknowns;
  Eigen::MatrixXd reduced, covariance;
  internal::PoseErrorColumns pose_errors;
  if (dof > 0) {
    report->pixel_noise_estimate_px = data.sigma_px * std::sqrt(2.0 * final_cost / dof);
    report->residual_dof = dof;
  }
  if (dof <= 0) {
    report->covariance_message = "uncertainty unavailable (no redundancy)";
  } else if (!internal::ReducedJacobian(data, state, columns, &reduced,
                                        options.estimate_pose_error ? &pose_errors : nullptr)) {
    report->covariance_message = "uncertainty unavailable (a dot ended behind a camera)";
  } else if (internal::CovarianceFromJacobian(reduced.leftCols(columns.size()),
                                              internal::GlobalNames(columns, data.robot.num_joints()), &covariance,
                                              &report->covariance_message)) {
    const double s2 = 2.0 * final_cost / dof;
    report->covariance_free = s2 * covariance;
    if (options.estimate_pose_error) {
      const std::vector<Eigen::MatrixXd> motions = JointMotions(data, state);
      report->error_model = internal::EstimateErrorModel(reduced, columns.size(), pose_errors.gradient,
                                                         pose_errors.residual_sq, dof, data.sigma_px,
                                                         Eigen::VectorXd(), motions);
      if (report->error_model.estimated) {
        report->covariance_free = internal::ModelCovariance(reduced, columns.size(), covariance, report->error_model,
                                                            data.sigma_px, &report->covariance_pose_part, motions);
      }
    }
    report->covariance_available = true;
    const Eigen::VectorXd sd = report->covariance_free.diagonal().array().sqrt();
    report->correlation_free = report->covariance_free;
    for (int i = 0; i < sd.size(); ++i) {
      for (int j = 0; j < sd.size(); ++j) {
        report->correlation_free(i, j) =
            sd[i] > 0 && sd[j] > 0 ? report->covariance_free(i, j) / (sd[i] * sd[j]) : 0.0;
      }
    }
    const int nk = static_cast<int>(columns.kinematic.size());
    for (int k = 0; k < nk; ++k) report->stddev[columns.kinematic[k]] = sd[k];
    for (size_t k = 0; k < columns.intrinsics.size(); ++k) report->intrinsics_stddev[columns.intrinsics[k]] = sd[nk + k];
    report->fx_stddev = report->intrinsics_stddev[kFx];
  }
}

// The score test of the parameters held by request (`held`, and the intrinsics the request estimates
// but the names hold) at the solution, under the estimated error model (error_model.h).
void TestHeldParameters(const BundleData& data, const BundleState& state, const std::vector<int>& free,
                        const BundleOptions& options, const std::vector<int>& held, const IntrinsicsMask& requested,
                        BundleReport* report) {
  internal::GlobalColumns columns;
  columns.kinematic = free;
  columns.intrinsics = EstimatedIntrinsics(options.intrinsics);
  const int num_free = columns.size();
  std::vector<int> held_intrinsics;
  for (int i = 0; i < kNumIntrinsics; ++i) {
    if (requested[i] && !options.intrinsics[i]) held_intrinsics.push_back(i);
  }
  if ((held.empty() && held_intrinsics.empty()) || !report->covariance_available) return;
  // Order [free kinematic | held kinematic], [free intrinsics | held intrinsics]; permuted to free | held below.
  columns.kinematic.insert(columns.kinematic.end(), held.begin(), held.end());
  const int num_kinematic = static_cast<int>(columns.kinematic.size());
  const int num_estimated = static_cast<int>(columns.intrinsics.size());
  columns.intrinsics.insert(columns.intrinsics.end(), held_intrinsics.begin(), held_intrinsics.end());
  Eigen::MatrixXd reduced;
  internal::PoseErrorColumns pose;
  if (!internal::ReducedJacobian(data, state, columns, &reduced, &pose)) return;
  const std::vector<std::string> all = internal::GlobalNames(columns, data.robot.num_joints());
  std::vector<int> order;
  for (int c = 0; c < static_cast<int>(free.size()); ++c) order.push_back(c);
  for (int c = 0; c < num_estimated; ++c) order.push_back(num_kinematic + c);
  std::vector<std::string> names;
  for (int c = static_cast<int>(free.size()); c < num_kinematic; ++c) order.push_back(c);
  for (int c = num_kinematic + num_estimated; c < columns.size(); ++c) order.push_back(c);
  for (int k = num_free; k < columns.size(); ++k) names.push_back(all[order[k]]);
  Eigen::MatrixXd permuted(reduced.rows(), reduced.cols());
  Eigen::VectorXd gradient(columns.size() - num_free), norm_sq(columns.size() - num_free);
  for (int k = 0; k < columns.size(); ++k) permuted.col(k) = reduced.col(order[k]);
  permuted.rightCols(reduced.cols() - columns.size()) = reduced.rightCols(reduced.cols() - columns.size());
  for (int k = num_free; k < columns.size(); ++k) {
    gradient[k - num_free] = pose.global_gradient[order[k]];
    norm_sq[k - num_free] = pose.global_norm_sq[order[k]];
  }
  const double s = report->pixel_noise_estimate_px / data.sigma_px;
  // The error model of the fit with the held parameters freed (one linear step): a wrong held value leaves a
  // pose error behind that would otherwise be taken as the cell's noise and hide it.
  ErrorModel freed = report->error_model;
  const std::vector<Eigen::MatrixXd> motions = JointMotions(data, state);
  if (options.estimate_pose_error) {
    Eigen::VectorXd global_gradient = Eigen::VectorXd::Zero(columns.size());
    global_gradient.tail(gradient.size()) = gradient;
    freed = internal::EstimateErrorModel(permuted, columns.size(), pose.gradient, pose.residual_sq,
                                         report->residual_dof - static_cast<int>(gradient.size()), data.sigma_px,
                                         global_gradient, motions);
    if (!freed.estimated) freed = report->error_model;
  }
  report->held_values =
      internal::TestHeldValues(permuted, num_free, names, gradient, norm_sq, freed, data.sigma_px, s * s, motions);
  report->held_values.decisive =
      options.free_parameters.empty() &&
      std::find(options.held_parameters.begin(), options.held_parameters.end(), "kinematics") == options.held_parameters.end();
}

}  // namespace

BundleReport RunBundleAdjustment(const ObservationSet& observations, const Eigen::VectorXd& rho_start,
                                 double fx_start, const BundleOptions& requested) {
  const auto start = Clock::now();
  BundleReport report;
  report.rho = rho_start;
  report.fx_px = fx_start;
  report.intrinsics = IntrinsicsOf(observations.camera);
  report.intrinsics[kFx] = fx_start;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  report.stddev = Eigen::VectorXd::Constant(std::max<Eigen::Index>(rho_start.size(), 0), nan);
  report.fx_stddev = nan;
  report.intrinsics_stddev.fill(nan);
  auto finish = [&](Outcome outcome, const std::string& message) {
    report.outcome = outcome;
    report.message = message;
    report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return report;
  };

  BundleOptions options = requested;
  std::vector<int> held;
  std::string problems = CheckInputs(observations, rho_start, fx_start, options);
  problems += HeldParameters(observations.robot.num_joints(), &options, &held);
  if (problems.empty() && static_cast<int>(held.size()) == observations.robot.num_parameters() &&
      EstimatedIntrinsics(options.intrinsics).empty()) {
    problems = "the held and free parameters asked for hold every kinematic, hand-eye and camera parameter: nothing "
               "is left to estimate\n";
  }
  if (!problems.empty()) return finish(Outcome::kInvalidInput, "invalid input:\n" + problems);
  report.intrinsics_estimated = options.intrinsics;
  const int num_poses = static_cast<int>(observations.PosesWithRole(PoseRole::kIdentification).size());
  if (num_poses < options.min_identification_poses) {
    return finish(Outcome::kDegenerate, "only " + std::to_string(num_poses) + " identification poses (need " +
                                            std::to_string(options.min_identification_poses) + ")");
  }
  const bool flange_poses = observations.UsesFlangePoses();
  if (observations.yardsticks.empty() && !flange_poses) {
    return finish(Outcome::kScaleUnresolved, "no yardstick: the metric scale is unobservable from images alone");
  }
  BundleData data = internal::MakeBundleData(observations, options.yardstick_sigma_m);
  report.dropped_dots = DotsSeenOnce(observations);
  BundleState state;
  state.rho = rho_start;
  state.intrinsics = report.intrinsics;
  TriangulateStartDots(rho_start, &data, &state, &report.dropped_dots);
  if (data.yardsticks.empty() && !flange_poses) {
    return finish(Outcome::kScaleUnresolved,
                  "no yardstick has both ends seen (and triangulable) in two or more identification poses");
  }
  if (!data.yardsticks.empty()) report.yardstick_sigma_m = options.yardstick_sigma_m;
  if (data.observations.empty()) {
    return finish(Outcome::kDegenerate, "no dot could be placed: each of the " +
                                            std::to_string(report.dropped_dots.size()) +
                                            " was seen in fewer than two identification poses or was not "
                                            "triangulable from the start's cameras");
  }

  internal::Gauge gauge;
  if (!AnalyzeStartGauge(data, state, options, held, &gauge, &report)) {
    return finish(Outcome::kFailure, "the start model puts a triangulated dot behind a camera");
  }
  const std::string not_identifiable = WhyNotIdentifiable(gauge, options, num_poses, report.generic_rank);
  if (!not_identifiable.empty()) return finish(Outcome::kDegenerate, not_identifiable);
  if (!HoldWeakParameters(data, options, &gauge, &state, &report)) {
    return finish(Outcome::kFailure, "the nominal model puts a triangulated dot behind a camera");
  }

  const ScreenedFit fit = SolveScreened(gauge.free_kinematic, options, &data, &state, &report);
  if (fit.scale_lost) {
    return finish(Outcome::kScaleUnresolved, "the residual screen removed " + std::to_string(report.removed.size()) +
                                                 " observations, among them the yardstick's views (the solve before it "
                                                 "had not found the images' geometry: a poor start)");
  }
  internal::LmSummary summary = fit.summary;
  const auto failed = [&report](const internal::LmSummary& fit_summary) {
    report.final_cost = fit_summary.final_cost;
    report.termination = std::string(internal::TerminationName(fit_summary.termination)) + ": " + fit_summary.message;
    return fit_summary.termination == internal::LmSummary::Termination::kFailure;
  };
  if (failed(summary)) return finish(Outcome::kFailure, "solver failed: " + report.termination);
  RecordSolution(data, state, &report);
  EstimateCovariance(data, state, gauge.free_kinematic, options, summary.final_cost, &report);
  // At most one round per free parameter; each holds one.
  for (size_t round = 0; round < report.free_indices.size() &&
                         internal::HoldWeakestUnderErrorModel(data, options, &gauge, &state, &report);
       ++round) {
    summary = Solve(data, gauge.free_kinematic, options, false, &state);
    report.iterations += summary.iterations;
    if (failed(summary)) return finish(Outcome::kFailure, "solver failed: " + report.termination);
    RecordSolution(data, state, &report);
    EstimateCovariance(data, state, gauge.free_kinematic, options, summary.final_cost, &report);
  }
  const bool converged = summary.termination == internal::LmSummary::Termination::kConvergence;
  TestHeldParameters(data, state, gauge.free_kinematic, options, held, requested.intrinsics, &report);

  std::ostringstream msg;
  msg << (converged ? "converged" : "not converged") << ": "
      << report.num_observations << " observations of " << data.dot_ids.size() << " dots in " << num_poses
      << " poses, " << report.free_indices.size() << (flange_poses ? " free hand-eye parameters, " : " free kinematic parameters, ") << report.removed.size()
      << " observations removed by the screen, RMS " << report.rms_reprojection_px << " px";
  return finish(converged ? Outcome::kConverged : Outcome::kNoConvergence,
                msg.str());
}

}  // namespace selfcal::bundle
