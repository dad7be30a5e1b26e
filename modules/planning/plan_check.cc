#include "planning/plan_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "base/status.h"
#include "identification/identifiability.h"
#include "planning/observability.h"
#include "planning/view_geometry.h"

namespace selfcal::planning {

namespace {

std::string Fmt(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// The session's pose ids (p00, p01, ...) unless the plan names its poses.
thread_local const std::vector<std::string>* g_pose_ids = nullptr;

std::string PoseName(int i) {
  if (g_pose_ids != nullptr && i >= 0 && i < static_cast<int>(g_pose_ids->size())) return "pose " + (*g_pose_ids)[i];
  char id[16];
  std::snprintf(id, sizeof(id), "p%02d", i);
  return std::string("pose ") + id;
}

// Names the poses of one check by `ids` (empty: the default) for its lifetime.
class PoseIds {
 public:
  explicit PoseIds(const std::vector<std::string>& ids) : saved_(g_pose_ids) { g_pose_ids = ids.empty() ? nullptr : &ids; }
  ~PoseIds() { g_pose_ids = saved_; }
  PoseIds(const PoseIds&) = delete;
  PoseIds& operator=(const PoseIds&) = delete;

 private:
  const std::vector<std::string>* saved_;
};

void Add(PlanCheck* check, PlanIssue issue, int pose, int other, const std::string& message) {
  check->problems.push_back({issue, pose, other, message});
}

// C5: every pose has one finite value per joint. A partial plan changes the observability of the
// experiment, so any bad pose refuses the whole plan.
void CheckJointValues(int n, const std::vector<Eigen::VectorXd>& poses, PlanCheck* check) {
  for (size_t k = 0; k < poses.size(); ++k) {
    const int i = static_cast<int>(k);
    if (poses[i].size() != n) {
      Add(check, PlanIssue::kJointCount, i, -1,
          PoseName(i) + " has " + std::to_string(poses[i].size()) + " joint values, the robot has " + std::to_string(n));
    } else if (!poses[i].allFinite()) {
      Add(check, PlanIssue::kNonFinite, i, -1, PoseName(i) + " has a non-finite joint value");
    }
  }
}

// C7: enough identification poses.
void CheckPoseCount(const PlanningProblem& problem, int m, PlanCheck* check) {
  const int m_id = problem.num_identification_poses;
  if (m < m_id || m_id < problem.constraints.min_identification_poses) {
    Add(check, PlanIssue::kTooFewPoses, -1, -1,
        "the plan has " + std::to_string(m) + " poses; " + std::to_string(m_id) +
            " identification poses are asked for and at least " +
            std::to_string(problem.constraints.min_identification_poses) + " are needed");
  }
}

// The limits a plan must keep: the robot config's, narrowed by the controller's where they are narrower.
struct Limits {
  Eigen::VectorXd lower, upper;
  std::vector<bool> from_controller;
};

Limits EffectiveLimits(const RobotModel* robot, const ControllerLimits* controller, int n) {
  Limits l;
  l.lower = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  l.upper = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  l.from_controller.assign(n, false);
  for (int j = 0; robot != nullptr && j < n; ++j) {
    l.lower[j] = robot->limits[j].min_rad;
    l.upper[j] = robot->limits[j].max_rad;
  }
  if (controller != nullptr && controller->lower_rad.size() == n && controller->upper_rad.size() == n) {
    for (int j = 0; j < n; ++j) {
      if (controller->lower_rad[j] > l.lower[j] || controller->upper_rad[j] < l.upper[j]) l.from_controller[j] = true;
      l.lower[j] = std::max(l.lower[j], controller->lower_rad[j]);
      l.upper[j] = std::min(l.upper[j], controller->upper_rad[j]);
    }
  }
  return l;
}

// C6: joint limits less the margin; no clamping.
void CheckJointLimits(const Limits& limits, double margin_rad, const std::vector<Eigen::VectorXd>& poses,
                      PlanCheck* check) {
  const int n = static_cast<int>(limits.lower.size());
  const int m = static_cast<int>(poses.size());
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      const double lo = limits.lower[j] + margin_rad, hi = limits.upper[j] - margin_rad;
      if (poses[i][j] < lo || poses[i][j] > hi) {
        Add(check, PlanIssue::kJointLimit, i, -1,
            PoseName(i) + " joint " + std::to_string(j + 1) + " = " + Fmt("%.3f", RadToDeg(poses[i][j])) +
                " deg is outside [" + Fmt("%.3f", RadToDeg(lo)) + ", " + Fmt("%.3f", RadToDeg(hi)) + "] deg (" +
                (limits.from_controller[j] ? "the controller's limits" : "limits") + " less the " +
                Fmt("%.1f", RadToDeg(margin_rad)) + " deg margin)");
      }
    }
  }
}

// R3: the controller's velocity limits time and bound every move.
void CheckVelocityLimits(const ControllerLimits& controller, int n, PlanCheck* check) {
  if (controller.max_velocity_rad_s.size() != n) {
    Add(check, PlanIssue::kVelocityLimit, -1, -1,
        "the robot reports " + std::to_string(controller.max_velocity_rad_s.size()) +
            " joint velocity limits for " + std::to_string(n) + " joints: moves cannot be timed or bounded");
    return;
  }
  for (int j = 0; j < n; ++j) {
    if (!(controller.max_velocity_rad_s[j] > 0 && std::isfinite(controller.max_velocity_rad_s[j]))) {
      Add(check, PlanIssue::kVelocityLimit, -1, -1,
          "joint " + std::to_string(j + 1) + ": velocity limit " + Fmt("%g", controller.max_velocity_rad_s[j]) +
              " rad/s is not a positive number");
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

// Eye-to-hand: the plate faces the fixed camera at every pose (PlanConstraints::max_viewing_angle_rad).
void CheckViewingAngles(const PlanningProblem& problem, const std::vector<Rigid3>& flange_from_cam, PlanCheck* check) {
  const double bound = problem.constraints.max_viewing_angle_rad;
  const Eigen::Vector3d centre = problem.scene.Centre();
  for (size_t i = 0; i < flange_from_cam.size(); ++i) {
    const double angle = PlateViewingAngle(flange_from_cam[i], centre);
    if (angle > bound) {
      Add(check, PlanIssue::kViewingAngle, static_cast<int>(i), -1,
          PoseName(static_cast<int>(i)) + ": the plate on the flange is seen " + Fmt("%.1f", RadToDeg(angle)) +
              " deg off its normal by the fixed camera, more than " + Fmt("%.1f", RadToDeg(bound)) + " deg");
    }
  }
}

// Spread (duplicates, C7): camera centres at least min_spread_m apart. Each pose too close to an earlier
// one is named once, with the first such pose: one problem per pair made a plan of n copies of one pose
// n^2 / 2 problems (42,000 copies, the mutation campaign's, grew plan --check to 22 GB).
void CheckSpread(const PlanConstraints& c, const std::vector<Rigid3>& base_from_cam, PlanCheck* check) {
  const int m = static_cast<int>(base_from_cam.size());
  check->min_spread_m = std::numeric_limits<double>::infinity();
  for (int k = 1; k < m; ++k) {
    bool named = false;
    for (int i = 0; i < k; ++i) {
      const double d = (base_from_cam[i].translation - base_from_cam[k].translation).norm();
      check->min_spread_m = std::min(check->min_spread_m, d);
      if (d < c.min_spread_m && !named) {
        named = true;
        Add(check, PlanIssue::kTooClose, i, k,
            PoseName(i) + " and " + PoseName(k) + ": camera centres " + Fmt("%.4f", d) + " m apart, less than " +
                Fmt("%.4f", c.min_spread_m) + " m");
      }
    }
  }
}

// The paper method's f_x from every pair (reference, i), i < m_id: a figure (pairs below 0.08), and a
// constraint only when c.min_axis_sine > 0.
void CheckAxisSines(const PlanConstraints& c, const std::vector<Rigid3>& base_from_cam, int m_id, PlanCheck* check) {
  constexpr double kPaperAxisSine = 0.08;
  check->min_axis_sine = std::numeric_limits<double>::infinity();
  for (int i = 1; i < m_id; ++i) {
    const double s = AxisSine<double>(base_from_cam[0], base_from_cam[i]);
    check->min_axis_sine = std::min(check->min_axis_sine, s);
    if (s < kPaperAxisSine) ++check->pairs_below_paper_axis_sine;
    if (c.min_axis_sine > 0 && s < c.min_axis_sine) {
      Add(check, PlanIssue::kAxesIntersect, 0, i,
          PoseName(0) + " (reference) and " + PoseName(i) + ": optical axes nearly intersect (axis sine " +
              Fmt("%.4f", s) + " < " + Fmt("%.4f", c.min_axis_sine) +
              "); the paper method's f_x is unobservable from this pair");
    }
  }
}

// f_x from the identification poses as a set: the bundle's Cramer-Rao bound (dots unknown), from the
// observability report of the identification poses.
void CheckFocalObservability(const PlanningProblem& problem, const ObservabilityReport& r, PlanCheck* check) {
  const PlanConstraints& c = problem.constraints;
  const double bound_px = c.max_fx_stddev_rel * problem.camera.fx_px;
  check->predicted_fx_stddev_px = r.prediction_ok ? r.predicted_fx_stddev_px : std::numeric_limits<double>::infinity();
  if (!(check->predicted_fx_stddev_px <= bound_px)) {
    Add(check, PlanIssue::kFxUnobservable, -1, -1,
        "the identification poses determine f_x to " + Fmt("%.3g", check->predicted_fx_stddev_px) + " px (" +
            Fmt("%.2f", c.pixel_noise_px) + " px noise, the bundle adjustment's Cramer-Rao bound), more than " +
            Fmt("%.3g", bound_px) + " px (" + Fmt("%.4g", c.max_fx_stddev_rel) + " of f_x)");
  }
}

// Joint travel between consecutive poses.
void CheckJointTravel(double max_travel_rad, const std::vector<Eigen::VectorXd>& poses, int n, PlanCheck* check) {
  const int m = static_cast<int>(poses.size());
  check->max_joint_travel_rad = 0;
  for (int i = 1; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      const double travel = std::abs(poses[i][j] - poses[i - 1][j]);
      check->max_joint_travel_rad = std::max(check->max_joint_travel_rad, travel);
      if (travel > max_travel_rad) {
        Add(check, PlanIssue::kJointTravel, i - 1, i,
            PoseName(i - 1) + " -> " + PoseName(i) + ": joint " + std::to_string(j + 1) + " moves " +
                Fmt("%.2f", RadToDeg(travel)) + " deg, more than " + Fmt("%.2f", RadToDeg(max_travel_rad)) +
                " deg; add an intermediate pose");
      }
    }
  }
}

// Image motion of every move between consecutive poses (what tracking through the move must carry).
void CheckImageMotion(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses, PlanCheck* check) {
  const double bound = problem.constraints.max_image_motion_px;
  check->max_image_motion_px = 0;
  for (size_t k = 1; k < poses.size(); ++k) {
    const int i = static_cast<int>(k);
    const MoveImageMotion motion = ImageMotionOfMove(problem, poses[i - 1], poses[i]);
    check->image_motion.push_back({i, motion.common_dots, motion.median_px, motion.max_px});
    check->max_image_motion_px = std::max(check->max_image_motion_px, motion.median_px);
    if (!(motion.median_px <= bound)) {
      Add(check, PlanIssue::kImageMotion, i - 1, i,
          PoseName(i - 1) + " -> " + PoseName(i) + ": the scene's dots move " + Fmt("%.1f", motion.median_px) +
              " px in the image (median of " + std::to_string(motion.common_dots) + " dots, largest " +
              Fmt("%.1f", motion.max_px) + " px), more than " + Fmt("%.1f", bound) +
              " px; tracking through the move would lose them: add an intermediate pose");
    }
  }
}

// Observability of the identification poses (C7, K3), at the nominal model rho: `id` is their
// identifiability analysis, `generic_identifiable` the rank generic poses of the robot reach (-1: computed here).
void CheckObservability(const PlanningProblem& problem, const identification::IdentifiabilityReport& id,
                        int generic_identifiable, PlanCheck* check) {
  const RobotModel& robot = problem.robot;
  const PlanConstraints& c = problem.constraints;
  check->identifiable = id.rank;
  check->generic_identifiable =
      generic_identifiable >= 0 ? generic_identifiable : GenericIdentifiable(robot);
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
    case PlanIssue::kFxUnobservable: return "fx_unobservable";
    case PlanIssue::kImageMotion: return "image_motion";
    case PlanIssue::kRobotMismatch: return "robot_mismatch";
    case PlanIssue::kVelocityLimit: return "velocity_limit";
    case PlanIssue::kViewingAngle: return "viewing_angle";
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

namespace {

// Every constraint of CheckPlan that needs the scene and camera, on poses with usable joint values.
void CheckGeometry(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses, int generic_identifiable,
                   PlanCheck* check) {
  const RobotModel& robot = problem.robot;
  const PlanConstraints& c = problem.constraints;
  const int m = static_cast<int>(poses.size());
  CheckPoseCount(problem, m, check);
  if (m < problem.num_identification_poses) return;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  std::vector<Rigid3> base_from_cam(m);
  for (int i = 0; i < m; ++i) base_from_cam[i] = PointsFromCam(robot, rho, poses[i]);
  // Every scene point in every image. Points: the extent (box corners or every dot), then every dot.
  std::vector<Eigen::Vector3d> points = problem.scene.extent_in_base;
  points.insert(points.end(), problem.scene.dots_in_base.begin(), problem.scene.dots_in_base.end());
  check->min_image_margin_px = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) CheckViewOfScene(problem, points, i, base_from_cam[i], check);
  if (robot.mount == CameraMount::kEyeToHand) CheckViewingAngles(problem, base_from_cam, check);
  CheckSpread(c, base_from_cam, check);
  CheckAxisSines(c, base_from_cam, problem.num_identification_poses, check);
  CheckImageMotion(problem, poses, check);
  // One identifiability analysis of the identification poses for the excitation and f_x checks.
  identification::IdentifiabilityReport id;
  check->observability = AnalyzeObservability(problem, poses, c.pixel_noise_px, &id);
  CheckObservability(problem, id, generic_identifiable, check);
  CheckFocalObservability(problem, check->observability, check);
}

}  // namespace

std::vector<Eigen::Vector2d> DotImages(const PlanningProblem& problem, const Eigen::VectorXd& q) {
  const Rigid3 cam_from_base = PointsFromCam(problem.robot, KinematicParameters::Nominal(problem.robot), q).Inverse();
  std::vector<Eigen::Vector2d> uv;
  uv.reserve(problem.scene.dots_in_base.size());
  for (const Eigen::Vector3d& x : problem.scene.dots_in_base) {
    const Eigen::Vector3d p = cam_from_base * x;
    double u = 0, v = 0;
    if (p.z() > 0) ProjectPoint<double>(problem.camera, problem.camera.fx_px, problem.camera.k1, p, &u, &v);
    const bool seen = p.z() > 0 && ImageMargin(problem.camera, u, v) >= 0;
    uv.emplace_back(seen ? u : std::nan(""), seen ? v : std::nan(""));
  }
  return uv;
}

MoveImageMotion ImageMotionBetween(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to) {
  thread_local std::vector<double> shifts;  // the planner asks this tens of thousands of times: no allocation each
  shifts.clear();
  for (size_t k = 0; k < from.size() && k < to.size(); ++k) {
    if (from[k].allFinite() && to[k].allFinite()) shifts.push_back((to[k] - from[k]).norm());
  }
  MoveImageMotion motion;
  motion.common_dots = static_cast<int>(shifts.size());
  if (shifts.empty()) {
    motion.median_px = motion.max_px = std::numeric_limits<double>::infinity();
    return motion;
  }
  // The element a sort would put at size / 2 (nth_element: the planner asks this thousands of times).
  motion.max_px = *std::max_element(shifts.begin(), shifts.end());
  std::nth_element(shifts.begin(), shifts.begin() + shifts.size() / 2, shifts.end());
  motion.median_px = shifts[shifts.size() / 2];
  return motion;
}

MoveImageMotion ImageMotionOfMove(const PlanningProblem& problem, const Eigen::VectorXd& q_from,
                                  const Eigen::VectorXd& q_to) {
  return ImageMotionBetween(DotImages(problem, q_from), DotImages(problem, q_to));
}

int GenericIdentifiable(const RobotModel& robot) {
  return identification::GenericRank(robot, KinematicParameters::Nominal(robot),
                                     identification::IdentifiabilityOptions().rank_tolerance);
}

PlanCheck CheckPlan(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses, int generic_identifiable) {
  const std::string invalid = problem.Validate();
  SELFCAL_CHECK(invalid.empty(), "planning problem: " << invalid);
  PlanCheck check;
  const RobotModel& robot = problem.robot;
  const PlanConstraints& c = problem.constraints;
  CheckJointValues(robot.num_joints(), poses, &check);
  CheckPoseCount(problem, static_cast<int>(poses.size()), &check);
  if (!check.problems.empty()) return check;
  CheckJointLimits(EffectiveLimits(&robot, nullptr, robot.num_joints()), c.joint_margin_rad, poses, &check);
  CheckJointTravel(c.max_joint_travel_rad, poses, robot.num_joints(), &check);
  CheckGeometry(problem, poses, generic_identifiable, &check);
  check.ok = check.problems.empty();
  return check;
}

PlanCheck CheckPlanFor(const RobotModel* robot, const PlanSubject& plan, const ControllerLimits* controller) {
  const PoseIds ids(plan.pose_ids);
  PlanCheck check;
  const int n = robot != nullptr ? robot->num_joints() : controller != nullptr ? static_cast<int>(controller->lower_rad.size()) : 0;
  if (robot != nullptr && !plan.robot.empty() && plan.robot != robot->name) {
    Add(&check, PlanIssue::kRobotMismatch, -1, -1,
        "the plan is for robot `" + plan.robot + "`, the robot config is for `" + robot->name + "`");
  }
  if (plan.poses.empty()) Add(&check, PlanIssue::kTooFewPoses, -1, -1, "the plan has no poses");
  CheckJointValues(n, plan.poses, &check);
  if (controller != nullptr) CheckVelocityLimits(*controller, n, &check);
  const PlanConstraints c = plan.planned_for ? plan.planned_for->constraints : PlanConstraints();
  const double margin = plan.planned_for ? c.joint_margin_rad : plan.joint_margin_rad;
  const double travel = plan.planned_for ? c.max_joint_travel_rad : plan.max_joint_travel_rad;
  check.scope.push_back(std::string("robot level: robot name, joint count, finite values, joint limits") +
                        (controller != nullptr ? " (config and controller)" : " (config)") + " less " +
                        Fmt("%.1f", RadToDeg(margin)) + " deg, travel per move up to " + Fmt("%.1f", RadToDeg(travel)) +
                        " deg" + (controller != nullptr ? ", velocity limits" : ""));
  if (!plan.planned_for) {
    check.scope.push_back(
        "the plan records no `planned_for` block (scene and camera): scene in image, depth, spread, f_x, "
        "excitation and image motion were not checked");
  }
  if (check.problems.empty()) {
    CheckJointLimits(EffectiveLimits(robot, controller, n), margin, plan.poses, &check);
    CheckJointTravel(travel, plan.poses, n, &check);
    const int m = static_cast<int>(plan.poses.size());
    const int identify = plan.num_identification_poses > 0 ? std::min(plan.num_identification_poses, m) : std::min(m, 15);
    check.barely_moving = BarelyMovingJoints({plan.poses.begin(), plan.poses.begin() + identify});
  }
  if (check.problems.empty() && plan.planned_for && robot != nullptr) {
    PlanningProblem problem;
    problem.robot = *robot;
    problem.robot.mount = plan.planned_for->configuration;  // the frame of its scene
    problem.robot.base_from_cam = plan.planned_for->base_from_cam;
    problem.camera = plan.planned_for->camera;
    problem.scene = plan.planned_for->scene;
    problem.constraints = c;
    const int m = static_cast<int>(plan.poses.size());
    problem.num_identification_poses = plan.num_identification_poses > 0 ? plan.num_identification_poses : std::min(m, 15);
    if (const std::string invalid = problem.Validate(); !invalid.empty()) {
      Add(&check, PlanIssue::kTooFewPoses, -1, -1, "the plan's `planned_for` block: " + invalid);
    } else {
      check.scope.push_back(std::string("geometry (planned_for, ") + CameraMountName(problem.robot.mount) + "): " +
                            std::to_string(problem.scene.dots_in_base.size()) +
                            " scene dots, " + std::to_string(problem.camera.width_px) + "x" +
                            std::to_string(problem.camera.height_px) + " px camera, f_x " +
                            Fmt("%.1f", problem.camera.fx_px) + " px: scene in image, depth, spread, f_x, "
                            "excitation, image motion up to " + Fmt("%.1f", c.max_image_motion_px) + " px per move");
      CheckGeometry(problem, plan.poses, -1, &check);
    }
  }
  check.ok = check.problems.empty();
  return check;
}

}  // namespace selfcal::planning
