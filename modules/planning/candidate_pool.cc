#include "planning/candidate_pool.h"

#include <cmath>
#include <random>

#include "base/status.h"
#include "planning/view_geometry.h"

namespace selfcal::planning {

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
  const Rigid3 cam_from_base = BaseFromCam(robot, KinematicParameters::Nominal(robot), q).Inverse();
  for (size_t k = 0; k < problem.scene.extent_in_base.size(); ++k) {
    const Eigen::Vector3d p = cam_from_base * problem.scene.extent_in_base[k];
    if (p.z() < c.min_depth_m || p.z() > c.max_depth_m) {
      if (reason) *reason = "scene point " + std::to_string(k) + " outside the depth range";
      return false;
    }
    double u = 0, v = 0;
    ProjectPoint<double>(problem.camera, problem.camera.fx_px, problem.camera.k1, p, &u, &v);
    if (ImageMargin(problem.camera, u, v) < c.image_margin_px) {
      if (reason) *reason = "scene point " + std::to_string(k) + " outside the image less the margin";
      return false;
    }
  }
  return true;
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
  std::vector<Eigen::VectorXd> pool;
  const int attempts = options.count * options.max_attempts_per_candidate;
  for (int attempt = 0; attempt < attempts && static_cast<int>(pool.size()) < options.count; ++attempt) {
    const Eigen::VectorXd& seed = templates[pick(rng)];
    const Rigid3 tmpl = BaseFromCam(robot, rho, seed);
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
    Eigen::VectorXd q;
    if (!SolveCameraIk(robot, rho, Rigid3(r, position), seed, &q)) continue;
    // Same arm and wrist configuration as the first template (no flips): within the travel bound of it.
    if ((q - templates[0]).lpNorm<Eigen::Infinity>() > problem.constraints.max_joint_travel_rad) continue;
    if (PoseFeasible(problem, q)) pool.push_back(q);
  }
  return pool;
}

}  // namespace selfcal::planning
