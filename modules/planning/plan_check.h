// Checks a measurement plan before the robot moves (issue 4 item 3; ../shared/RELIABILITY.md C5-C7): every
// constraint of PlanConstraints, pose by pose, each violation with the pose(s) and the value, and the
// observability of the identification poses (rank against generic poses, condition number).
//
// The planner (planning/planner.h) keeps its plans strictly inside the same constraints. CheckPlanFor is the
// one check of a plan file against a robot: `selfcal plan --check PLAN` and `selfcal run`'s preflight
// (acquisition/motion_safety.h) both call it and print its words.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/joint_motion.h"
#include "planning/observability.h"
#include "planning/plan_problem.h"

namespace selfcal::planning {

enum class PlanIssue {
  kJointCount,          // C5: a pose with the wrong number of joint values
  kNonFinite,           // C5: NaN or Inf
  kJointLimit,          // C6: outside the limits less the margin
  kTooFewPoses,         // C7: fewer identification poses than required, or no verification pose
  kTooClose,            // C7: two camera centres closer than min_spread_m (duplicates)
  kOutOfImage,          // a scene point outside the image less the margin
  kDepth,               // a scene point behind the camera, or nearer/farther than the depth range
  kAxesIntersect,       // f_x unobservable from the pair (reference, i): only when min_axis_sine > 0
  kJointTravel,         // a joint moves more than max_joint_travel_rad between consecutive poses
  kInsufficientExcitation,  // C7: rank below generic poses', or condition number above the bound
  kFxUnobservable,      // f_x not determined by the identification poses as a set (bundle's Cramer-Rao)
  kImageMotion,         // a move displaces the scene's dots in the image by more than the bound (median)
  kRobotMismatch,       // the plan file names another robot than the robot config
  kVelocityLimit,       // the controller reports no usable velocity limits (R3)
  kViewingAngle,        // eye-to-hand: the plate seen more obliquely than max_viewing_angle_rad
};
const char* PlanIssueName(PlanIssue issue);

struct PlanProblemItem {
  PlanIssue issue;
  int pose = -1;        // 0-based; -1 for the whole plan
  int other_pose = -1;  // the second pose of a pair, else -1
  std::string message;  // names the pose(s) (pose p03: the 0-based index), the quantity, its value and the bound
};

// The image motion of one move (pose - 1 -> pose) over the scene's dots seen at both ends.
struct MoveImageMotion {
  int pose = 0;             // the move's target
  int common_dots = 0;      // dots in the image at both ends
  double median_px = 0, max_px = 0;
};

struct PlanCheck {
  bool ok = false;  // no problem found
  std::vector<PlanProblemItem> problems;
  // What was checked, in words (CheckPlanFor: the same lines for `plan --check` and `run`).
  std::vector<std::string> scope;
  // Figures of the plan (when the joint values were usable).
  double min_spread_m = 0;          // smallest camera-centre distance between two poses
  double min_axis_sine = 0;         // smallest axis sine over the pairs (reference, i)
  int pairs_below_paper_axis_sine = 0;  // pairs (reference, i) below 0.08: the paper method loses their f_x
  double predicted_fx_stddev_px = 0;    // the bundle's Cramer-Rao f_x std of the identification poses
  std::vector<MoveImageMotion> image_motion;  // per move between consecutive poses
  double max_image_motion_px = 0;             // the largest median over the moves
  double min_image_margin_px = 0;   // smallest distance of a scene point to the image border
  double max_joint_travel_rad = 0;  // largest joint change between consecutive poses
  int identifiable = 0, generic_identifiable = 0;
  double condition_number = 0;      // column-normalised identification Jacobian (identification poses)
  // The observability report of the identification poses at constraints.pixel_noise_px (planning/observability.h),
  // made by the scene checks (ok false when they did not run).
  ObservabilityReport observability;
  // Joints that barely move over the identification poses (CheckPlanFor): a warning, not a problem; the
  // parameters beside such a joint are hard to tell apart, and calibrate holds the poorly determined ones.
  std::vector<BarelyMovingJoint> barely_moving;
  std::string Summary() const;      // one line per problem, or "plan ok"
};

// Checks `poses` (rad; the first problem.num_identification_poses identify, the rest verify; the first
// is the reference of the relative measurements) against every constraint of the problem. Never throws on
// bad pose data: that is what it reports. The planner's own feasibility test.
// generic_identifiable: GenericIdentifiable(problem.robot) when the caller has it (a planner checks several
// plans of one robot); -1: computed here.
PlanCheck CheckPlan(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                    int generic_identifiable = -1);

// How many parameters generic poses of the robot identify at its nominal model (identification::GenericRank
// at the default rank tolerance): the excitation check's reference.
int GenericIdentifiable(const RobotModel& robot);

// The scene dots' pixels at joints q (nominal model); NaN for a dot behind the camera or outside the image.
std::vector<Eigen::Vector2d> DotImages(const PlanningProblem& problem, const Eigen::VectorXd& q);
// The image motion between two such views over the dots seen in both (infinite when none is).
MoveImageMotion ImageMotionBetween(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);
// The image motion of the move q_from -> q_to over the problem's scene dots (nominal model).
MoveImageMotion ImageMotionOfMove(const PlanningProblem& problem, const Eigen::VectorXd& q_from,
                                  const Eigen::VectorXd& q_to);

// The joint limits a robot controller reports (robot::JointLimits' content; planning does not use robot/).
struct ControllerLimits {
  Eigen::VectorXd lower_rad, upper_rad, max_velocity_rad_s;
};

// A plan as its file gives it (io::PlanSubjectOf reads one).
struct PlanSubject {
  std::string robot;                    // the file's `robot:`; empty when it names none
  std::vector<Eigen::VectorXd> poses;   // rad
  int num_identification_poses = 0;     // 0: not given (then min(15, poses))
  std::optional<PlannedFor> planned_for;  // the scene, camera and constraints it was planned with
  std::vector<std::string> pose_ids;    // how messages name the poses; empty: p00, p01, ... (the session's)
  // Without planned_for: the margin and travel bound of the robot-level checks.
  double joint_margin_rad = PlanConstraints().joint_margin_rad;
  double max_joint_travel_rad = PlanConstraints().max_joint_travel_rad;
};

// The one check of a plan against a robot config (and, in `run`, the controller's limits): the robot
// name; joint count and finite values (C5); the limits less the margin, of the config and of the
// controller when given (C6); the joint travel per move (R2); the controller's velocity limits (R3); and,
// when the plan records `planned_for`, every constraint of CheckPlan (scene in image, depth, spread,
// f_x, excitation, image motion; in eye-to-hand the viewing angle) in the configuration it records (the
// robot's mount and fixed camera replaced by it: its scene is in that configuration's frame). Without `planned_for` only the robot-level checks run, with the
// default margin and travel bound, and `scope` says so.
// `robot` may be null (a session loop given no robot config): then only the controller's limits apply.
PlanCheck CheckPlanFor(const RobotModel* robot, const PlanSubject& plan, const ControllerLimits* controller);

}  // namespace selfcal::planning
