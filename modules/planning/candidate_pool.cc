#include "planning/candidate_pool.h"

#include <cmath>
#include <random>

#include "base/status.h"
#include "kinematics/damped_least_squares.h"
#include "planning/pose_twists.h"
#include "planning/view_geometry.h"

namespace selfcal::planning {

namespace {

// Every scene point of `base_from_cam`'s view in the depth range and inside the image by the margin less
// `slack_px` (the depth range widened by slack_m); *reason names the first that is not.
bool ViewFits(const PlanningProblem& problem, const Rigid3& base_from_cam, double slack_px, double slack_m,
              std::string* reason) {
  const PlanConstraints& c = problem.constraints;
  const Rigid3 cam_from_base = base_from_cam.Inverse();
  for (size_t k = 0; k < problem.scene.extent_in_base.size(); ++k) {
    const Eigen::Vector3d p = cam_from_base * problem.scene.extent_in_base[k];
    if (p.z() < c.min_depth_m - slack_m || p.z() > c.max_depth_m + slack_m) {
      if (reason) *reason = "scene point " + std::to_string(k) + " outside the depth range";
      return false;
    }
    double u = 0, v = 0;
    ProjectPoint<double>(problem.camera, problem.camera.fx_px, problem.camera.k1, p, &u, &v);
    if (ImageMargin(problem.camera, u, v) < c.image_margin_px - slack_px) {
      if (reason) *reason = "scene point " + std::to_string(k) + " outside the image less the margin";
      return false;
    }
  }
  if (problem.robot.mount == CameraMount::kEyeToHand &&
      PlateViewingAngle(base_from_cam, problem.scene.Centre()) > c.max_viewing_angle_rad) {
    if (reason) *reason = "the plate seen more obliquely than the viewing angle";
    return false;
  }
  return true;
}

// SolveCameraIk's damped least squares (kinematics/damped_least_squares.h: the same residual, steps and
// stopping rules) with the residual's Jacobian from the joints' spatial twists (planning/pose_twists.h) instead of
// autodiff through every parameter: the candidate pool solves thousands of these. Nominal model only.
bool SolveCameraIkNominal(const RobotModel& model, const Rigid3& target, const Eigen::VectorXd& seed,
                          Eigen::VectorXd* q) {
  const int n = model.num_joints();
  const Eigen::Matrix3d rt = target.rotation.transpose();
  Eigen::Matrix<double, 3, Eigen::Dynamic> omega, v;
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
    const Rigid3 base_from_cam = internal::ComputeJointTwists<double>(model, x.data(), &omega, &v);
    const Eigen::Matrix3d e = rt * base_from_cam.rotation;
    const Eigen::Vector3d c = base_from_cam.translation;
    r->resize(6);
    r->head<3>() = rt * (c - target.translation);
    (*r)[3] = 0.5 * (e(2, 1) - e(1, 2));
    (*r)[4] = 0.5 * (e(0, 2) - e(2, 0));
    (*r)[5] = 0.5 * (e(1, 0) - e(0, 1));
    jac->resize(6, n);
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d w = omega.col(j);
      jac->col(j).head<3>() = rt * (w.cross(c) + v.col(j));
      Eigen::Matrix3d wx;
      wx << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
      const Eigen::Matrix3d de = rt * wx * base_from_cam.rotation;
      jac->col(j).tail<3>() << 0.5 * (de(2, 1) - de(1, 2)), 0.5 * (de(0, 2) - de(2, 0)), 0.5 * (de(1, 0) - de(0, 1));
    }
  };
  Eigen::VectorXd x = seed;
  MinimiseDampedLeastSquares(evaluate, &x);
  const PoseDifference diff = ComparePoses(PointsFromCam(model, KinematicParameters::Nominal(model), x), target);
  *q = x;
  return diff.position_m < 1e-10 && diff.rotation_rad < 1e-10;
}

}  // namespace

bool PoseFeasible(const PlanningProblem& problem, const Eigen::VectorXd& q, std::string* reason) {
  const PlanConstraints& c = problem.constraints;
  const RobotModel& robot = problem.robot;
  if (q.size() != robot.num_joints() || !q.allFinite()) {
    if (reason) *reason = "bad joint vector";
    return false;
  }
  for (int j = 0; j < robot.num_joints(); ++j) {
    if (q[j] < robot.limits[j].min_rad + c.joint_margin_rad || q[j] > robot.limits[j].max_rad - c.joint_margin_rad) {
      if (reason) *reason = "joint " + std::to_string(j + 1) + " outside its limits less the margin";
      return false;
    }
  }
  return ViewFits(problem, PointsFromCam(robot, KinematicParameters::Nominal(robot), q), 0.0, 0.0, reason);
}

std::vector<Eigen::VectorXd> MakeCandidatePool(const PlanningProblem& problem,
                                               const std::vector<Eigen::VectorXd>& templates,
                                               const PoolOptions& options) {
  SELFCAL_CHECK(!templates.empty(), "the candidate pool needs at least one template pose");
  const RobotModel& robot = problem.robot;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  Eigen::Vector3d lo = problem.scene.extent_in_base[0], hi = lo;
  for (const Eigen::Vector3d& p : problem.scene.extent_in_base) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), fraction(0.0, 1.0);
  std::uniform_int_distribution<size_t> pick(0, templates.size() - 1);
  std::vector<Rigid3> template_views;  // each template's camera, once
  for (const Eigen::VectorXd& q : templates) template_views.push_back(PointsFromCam(robot, rho, q));
  std::vector<Eigen::VectorXd> pool;
  const int attempts = options.count * options.max_attempts_per_candidate;
  for (int attempt = 0; attempt < attempts && static_cast<int>(pool.size()) < options.count; ++attempt) {
    const size_t chosen = pick(rng);
    const Eigen::VectorXd& seed = templates[chosen];
    const Rigid3& tmpl = template_views[chosen];
    const Eigen::Vector3d w = tmpl.translation - centre;
    const double azimuth = options.azimuth_rad * unit(rng), elevation = options.elevation_rad * unit(rng);
    const double scale = options.distance_min + (options.distance_max - options.distance_min) * fraction(rng);
    const Eigen::Vector3d aim = centre + options.aim_fraction * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(half);
    const double roll = options.roll_rad * unit(rng);
    Eigen::Vector3d horizontal = Eigen::Vector3d::UnitZ().cross(w);
    if (horizontal.norm() < 1e-9) horizontal = Eigen::Vector3d::UnitX();
    const Eigen::Vector3d dir = (Eigen::AngleAxisd(azimuth, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(elevation, horizontal.normalized()) * w)
                                    .normalized();
    const Eigen::Vector3d position = centre + scale * w.norm() * dir;
    const Eigen::Vector3d z = (aim - position).normalized();
    Eigen::Vector3d x = tmpl.rotation.col(0) - tmpl.rotation.col(0).dot(z) * z;
    if (x.norm() < 1e-6) continue;
    x = Eigen::AngleAxisd(roll, z) * x.normalized();
    Eigen::Matrix3d r;
    r.col(0) = x;
    r.col(1) = z.cross(x);
    r.col(2) = z;
    // The view is decided by the target pose (reached to 1e-10 m and rad when IK succeeds): a target that
    // breaks a view constraint by more than rounding is not solved for, which leaves the pool unchanged.
    const Rigid3 target(r, position);
    if (!ViewFits(problem, target, 1e-6, 1e-9, nullptr)) continue;
    Eigen::VectorXd q;
    if (!SolveCameraIkNominal(robot, target, seed, &q)) continue;
    // Same arm and wrist configuration as the first template (no flips): within the travel bound of it.
    if ((q - templates[0]).lpNorm<Eigen::Infinity>() > problem.constraints.max_joint_travel_rad) continue;
    if (PoseFeasible(problem, q)) pool.push_back(q);
  }
  return pool;
}

}  // namespace selfcal::planning
