#include "planning/plan_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "base/status.h"
#include "identification/identifiability.h"
#include "planning/view_geometry.h"

namespace selfcal::planning {

namespace {

std::string Fmt(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

std::string PoseName(int i) { return "pose " + std::to_string(i); }

void Add(PlanCheck* check, PlanIssue issue, int pose, int other, const std::string& message) {
  check->problems.push_back({issue, pose, other, message});
}

// C5: every pose has one finite value per joint, and there are enough poses. A partial plan changes
// the observability of the experiment, so any bad pose refuses the whole plan.
void CheckShape(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses, PlanCheck* check) {
  const PlanConstraints& c = problem.constraints;
  const int n = problem.robot.num_joints();
  const int m = static_cast<int>(poses.size());
  const int m_id = problem.num_identification_poses;
  for (int i = 0; i < m; ++i) {
    if (poses[i].size() != n) {
      Add(check, PlanIssue::kJointCount, i, -1,
          PoseName(i) + " has " + std::to_string(poses[i].size()) + " joint values, the robot has " + std::to_string(n));
    } else if (!poses[i].allFinite()) {
      Add(check, PlanIssue::kNonFinite, i, -1, PoseName(i) + " has a non-finite joint value");
    }
  }
  if (m < m_id || m_id < c.min_identification_poses) {
    Add(check, PlanIssue::kTooFewPoses, -1, -1,
        "the plan has " + std::to_string(m) + " poses; " + std::to_string(m_id) +
            " identification poses are asked for and at least " + std::to_string(c.min_identification_poses) +
            " are needed");
  }
}

// C6: joint limits less the margin; no clamping.
void CheckJointLimits(const RobotModel& robot, const PlanConstraints& c, const std::vector<Eigen::VectorXd>& poses,
                      PlanCheck* check) {
  const int n = robot.num_joints();
  const int m = static_cast<int>(poses.size());
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      const double lo = robot.limits[j].min_rad + c.joint_margin_rad, hi = robot.limits[j].max_rad - c.joint_margin_rad;
      if (poses[i][j] < lo || poses[i][j] > hi) {
        Add(check, PlanIssue::kJointLimit, i, -1,
            PoseName(i) + " joint " + std::to_string(j + 1) + " = " + Fmt("%.3f", RadToDeg(poses[i][j])) +
                " deg is outside [" + Fmt("%.3f", RadToDeg(lo)) + ", " + Fmt("%.3f", RadToDeg(hi)) +
                "] deg (limits less the " + Fmt("%.1f", RadToDeg(c.joint_margin_rad)) + " deg margin)");
      }
    }
  }
}

// Pose i sees every scene point in the image, at a sensible depth: the worst point is reported, and
// check->min_image_margin_px lowered to the smallest margin.
void CheckViewOfScene(const PlanningProblem& problem, const std::vector<Eigen::Vector3d>& points, int i,
                      const Rigid3& base_from_cam, PlanCheck* check) {
  const PlanConstraints& c = problem.constraints;
  const Rigid3 cam_from_base = base_from_cam.Inverse();
  int outside = 0, bad_depth = 0, worst_point = -1, worst_depth_point = -1;
  double worst_margin = std::numeric_limits<double>::infinity(), worst_depth = 0;
  Eigen::Vector2d worst_uv(0, 0);
  for (size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d p = cam_from_base * points[k];
    if (p.z() < c.min_depth_m || p.z() > c.max_depth_m) {
      if (bad_depth++ == 0 || std::abs(p.z() - 0.5 * (c.min_depth_m + c.max_depth_m)) >
                                  std::abs(worst_depth - 0.5 * (c.min_depth_m + c.max_depth_m))) {
        worst_depth = p.z();
        worst_depth_point = static_cast<int>(k);
      }
      if (p.z() <= 0) continue;
    }
    double u = 0, v = 0;
    ProjectPoint<double>(problem.camera, problem.camera.fx_px, problem.camera.k1, p, &u, &v);
    const double margin = ImageMargin(problem.camera, u, v);
    check->min_image_margin_px = std::min(check->min_image_margin_px, margin);
    if (margin < c.image_margin_px) ++outside;
    if (margin < worst_margin) {
      worst_margin = margin;
      worst_point = static_cast<int>(k);
      worst_uv = {u, v};
    }
  }
  const int total = static_cast<int>(points.size());
  if (bad_depth > 0) {
    Add(check, PlanIssue::kDepth, i, -1,
        PoseName(i) + ": " + std::to_string(bad_depth) + " of " + std::to_string(total) +
            " scene points outside the depth range [" + Fmt("%.3f", c.min_depth_m) + ", " +
            Fmt("%.3f", c.max_depth_m) + "] m (point " + std::to_string(worst_depth_point) + " at depth " +
            Fmt("%.3f", worst_depth) + " m)");
  }
  if (outside > 0) {
    Add(check, PlanIssue::kOutOfImage, i, -1,
        PoseName(i) + ": " + std::to_string(outside) + " of " + std::to_string(total) +
            " scene points closer than " + Fmt("%.1f", c.image_margin_px) + " px to the image border (point " +
            std::to_string(worst_point) + " at (" + Fmt("%.1f", worst_uv.x()) + ", " + Fmt("%.1f", worst_uv.y()) +
            ") px, " + Fmt("%.1f", worst_margin) + " px inside)");
  }
}

// Spread (duplicates, C7): camera centres at least min_spread_m apart.
void CheckSpread(const PlanConstraints& c, const std::vector<Rigid3>& base_from_cam, PlanCheck* check) {
  const int m = static_cast<int>(base_from_cam.size());
  check->min_spread_m = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) {
    for (int k = i + 1; k < m; ++k) {
      const double d = (base_from_cam[i].translation - base_from_cam[k].translation).norm();
      check->min_spread_m = std::min(check->min_spread_m, d);
      if (d < c.min_spread_m) {
        Add(check, PlanIssue::kTooClose, i, k,
            PoseName(i) + " and " + PoseName(k) + ": camera centres " + Fmt("%.4f", d) + " m apart, less than " +
                Fmt("%.4f", c.min_spread_m) + " m");
      }
    }
  }
}

// f_x observable from every pair (reference, i) of the paper's pipeline, i < m_id.
void CheckAxisSines(const PlanConstraints& c, const std::vector<Rigid3>& base_from_cam, int m_id, PlanCheck* check) {
  check->min_axis_sine = std::numeric_limits<double>::infinity();
  for (int i = 1; i < m_id; ++i) {
    const double s = AxisSine<double>(base_from_cam[0], base_from_cam[i]);
    check->min_axis_sine = std::min(check->min_axis_sine, s);
    if (s < c.min_axis_sine) {
      Add(check, PlanIssue::kAxesIntersect, 0, i,
          "pose 0 (reference) and " + PoseName(i) + ": optical axes nearly intersect (axis sine " + Fmt("%.4f", s) +
              " < " + Fmt("%.4f", c.min_axis_sine) + "); f_x is unobservable from this pair");
    }
  }
}

// Joint travel between consecutive poses.
void CheckJointTravel(const PlanConstraints& c, const std::vector<Eigen::VectorXd>& poses, int n, PlanCheck* check) {
  const int m = static_cast<int>(poses.size());
  check->max_joint_travel_rad = 0;
  for (int i = 1; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      const double travel = std::abs(poses[i][j] - poses[i - 1][j]);
      check->max_joint_travel_rad = std::max(check->max_joint_travel_rad, travel);
      if (travel > c.max_joint_travel_rad) {
        Add(check, PlanIssue::kJointTravel, i - 1, i,
            PoseName(i - 1) + " -> " + PoseName(i) + ": joint " + std::to_string(j + 1) + " moves " +
                Fmt("%.2f", RadToDeg(travel)) + " deg, more than " + Fmt("%.2f", RadToDeg(c.max_joint_travel_rad)) +
                " deg");
      }
    }
  }
}

// Observability of the identification poses (C7, K3), at the nominal model rho.
void CheckObservability(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                        const Eigen::VectorXd& rho, PlanCheck* check) {
  const RobotModel& robot = problem.robot;
  const PlanConstraints& c = problem.constraints;
  const std::vector<Eigen::VectorXd> id_poses(poses.begin(), poses.begin() + problem.num_identification_poses);
  identification::IdentifiabilityOptions id_options;
  const identification::IdentifiabilityReport id = identification::AnalyzeIdentifiability(robot, rho, id_poses, 0, id_options);
  check->identifiable = id.rank;
  check->generic_identifiable = identification::GenericRank(robot, rho, id_options.rank_tolerance);
  check->condition_number = id.condition_number;
  if (id.rank < check->generic_identifiable) {
    Add(check, PlanIssue::kInsufficientExcitation, -1, -1,
        "the identification poses identify " + std::to_string(id.rank) + " parameters, generic poses of this robot " +
            std::to_string(check->generic_identifiable) + " (a joint is not excited enough)");
  } else if (!(id.condition_number <= c.max_condition_number)) {
    Add(check, PlanIssue::kInsufficientExcitation, -1, -1,
        "condition number of the identification Jacobian " + Fmt("%.4g", id.condition_number) + " exceeds " +
            Fmt("%.4g", c.max_condition_number) + " (poses too similar)");
  }
}

}  // namespace

const char* PlanIssueName(PlanIssue issue) {
  switch (issue) {
    case PlanIssue::kJointCount: return "joint_count";
    case PlanIssue::kNonFinite: return "non_finite";
    case PlanIssue::kJointLimit: return "joint_limit";
    case PlanIssue::kTooFewPoses: return "too_few_poses";
    case PlanIssue::kTooClose: return "too_close";
    case PlanIssue::kOutOfImage: return "out_of_image";
    case PlanIssue::kDepth: return "depth";
    case PlanIssue::kAxesIntersect: return "axes_intersect";
    case PlanIssue::kJointTravel: return "joint_travel";
    case PlanIssue::kInsufficientExcitation: return "insufficient_excitation";
  }
  return "unknown";
}

std::string PlanCheck::Summary() const {
  if (problems.empty()) return "plan ok";
  std::ostringstream out;
  for (size_t i = 0; i < problems.size(); ++i) {
    out << (i ? "\n" : "") << PlanIssueName(problems[i].issue) << ": " << problems[i].message;
  }
  return out.str();
}

PlanCheck CheckPlan(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses) {
  const std::string invalid = problem.Validate();
  SELFCAL_CHECK(invalid.empty(), "planning problem: " << invalid);
  PlanCheck check;
  const RobotModel& robot = problem.robot;
  const PlanConstraints& c = problem.constraints;
  const int m = static_cast<int>(poses.size());
  CheckShape(problem, poses, &check);
  if (!check.problems.empty()) return check;
  CheckJointLimits(robot, c, poses, &check);

  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  std::vector<Rigid3> base_from_cam(m);
  for (int i = 0; i < m; ++i) base_from_cam[i] = BaseFromCam(robot, rho, poses[i]);
  // Every scene point in every image. Points: the extent (box corners or hull dots), then every dot.
  std::vector<Eigen::Vector3d> points = problem.scene.extent_in_base;
  points.insert(points.end(), problem.scene.dots_in_base.begin(), problem.scene.dots_in_base.end());
  check.min_image_margin_px = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) CheckViewOfScene(problem, points, i, base_from_cam[i], &check);

  CheckSpread(c, base_from_cam, &check);
  CheckAxisSines(c, base_from_cam, problem.num_identification_poses, &check);
  CheckJointTravel(c, poses, robot.num_joints(), &check);
  CheckObservability(problem, poses, rho, &check);
  check.ok = check.problems.empty();
  return check;
}

}  // namespace selfcal::planning
