#include "acquisition/motion_safety.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "geometry/rigid3.h"

namespace selfcal::acquisition {

std::string MotionSafetyOptions::Validate() const {
  std::ostringstream out;
  if (!(velocity_scaling > 0 && velocity_scaling <= 1)) {
    out << "velocity_scaling = " << velocity_scaling << " must lie in (0, 1]\n";
  }
  if (!(max_joint_travel_rad > 0 && std::isfinite(max_joint_travel_rad))) {
    out << "max_joint_travel = " << RadToDeg(max_joint_travel_rad) << " deg must be > 0\n";
  }
  if (!(limit_margin_rad >= 0 && std::isfinite(limit_margin_rad))) out << "limit_margin must be >= 0\n";
  if (!(start_tolerance_rad > 0 && std::isfinite(start_tolerance_rad))) out << "start_tolerance must be > 0\n";
  return out.str();
}

std::string PreflightRefusal(const std::vector<std::string>& problems) {
  std::string text = "preflight refused the plan:\n";
  for (const std::string& p : problems) text += "  " + p + "\n";
  return text;
}

std::vector<std::string> PreflightProblems(const planning::PlanCheck& check) {
  std::vector<std::string> lines;
  for (const planning::PlanProblemItem& p : check.problems) {
    lines.push_back(std::string(planning::PlanIssueName(p.issue)) + ": " + p.message);
  }
  return lines;
}

PreflightReport Preflight(const std::vector<PlannedPose>& plan, const robot::JointLimits& limits,
                          const Eigen::VectorXd& start_rad, const MotionSafetyOptions& options, int first_pose,
                          const PlanToCheck* whole_plan) {
  PreflightReport report;
  auto problem = [&](const std::string& text) { report.problems.push_back(text); };
  const std::string invalid = options.Validate();
  if (!invalid.empty()) problem("motion safety options: " + invalid.substr(0, invalid.size() - 1));
  const int n = static_cast<int>(limits.lower_rad.size());
  if (n == 0 || limits.upper_rad.size() != n) {
    problem("the robot reports no joint limits: refusing to move");
    return report;
  }
  if (plan.empty()) problem("the plan has no poses");
  if (start_rad.size() != n || !start_rad.allFinite()) {
    problem("the robot's current joint reading has " + std::to_string(start_rad.size()) +
            " values or non-finite ones; expected " + std::to_string(n) + " finite values");
  }
  if (!report.problems.empty()) return report;
  const planning::ControllerLimits controller{limits.lower_rad, limits.upper_rad, limits.max_velocity_rad_s};
  if (whole_plan != nullptr) {
    planning::PlanSubject subject = whole_plan->plan;
    subject.joint_margin_rad = std::max(subject.joint_margin_rad, options.limit_margin_rad);
    subject.max_joint_travel_rad = std::min(subject.max_joint_travel_rad, options.max_joint_travel_rad);
    report.check = planning::CheckPlanFor(&whole_plan->robot, subject, &controller);
  } else {
    planning::PlanSubject route;
    for (size_t i = static_cast<size_t>(first_pose); i < plan.size(); ++i) {
      route.poses.push_back(plan[i].joints_rad);
      route.pose_ids.push_back(plan[i].id);
    }
    route.joint_margin_rad = options.limit_margin_rad;
    route.max_joint_travel_rad = options.max_joint_travel_rad;
    report.check = planning::CheckPlanFor(nullptr, route, &controller);
  }
  for (const std::string& p : PreflightProblems(report.check)) problem(p);
  if (!report.problems.empty()) return report;

  char text[256];
  Eigen::VectorXd from = start_rad;
  std::string from_name = "the current position";
  for (size_t i = static_cast<size_t>(first_pose); i < plan.size(); ++i) {
    const PlannedPose& p = plan[i];
    MoveSummary move;
    move.pose = static_cast<int>(i);
    const Eigen::VectorXd travel = (p.joints_rad - from).cwiseAbs();
    int worst = 0;
    move.max_travel_rad = travel.maxCoeff(&worst);
    if (move.max_travel_rad > options.max_joint_travel_rad) {
      std::snprintf(text, sizeof(text),
                    "move %s -> pose %s: joint %d travels %.2f deg, more than the bound of %.2f deg; add an "
                    "intermediate pose",
                    from_name.c_str(), p.id.c_str(), worst + 1, RadToDeg(move.max_travel_rad),
                    RadToDeg(options.max_joint_travel_rad));
      problem(text);
    }
    move.duration_s = robot::QuinticMoveDuration(from, p.joints_rad, limits.max_velocity_rad_s,
                                                 options.velocity_scaling, &move.limiting_joint);
    report.total_motion_s += move.duration_s;
    report.moves.push_back(move);
    from = p.joints_rad;
    from_name = "pose " + p.id;
  }
  return report;
}

std::string PreflightReport::Preview(const std::vector<PlannedPose>& plan, double velocity_scaling) const {
  std::ostringstream out;
  char line[200];
  std::snprintf(line, sizeof(line), "%-6s %-14s %14s %14s %10s\n", "move", "to pose", "max travel deg",
                "limiting joint", "seconds");
  out << line;
  for (size_t k = 0; k < moves.size(); ++k) {
    const MoveSummary& m = moves[k];
    std::snprintf(line, sizeof(line), "%-6zu %-14s %14.2f %14d %10.2f\n", k + 1, plan[m.pose].id.c_str(),
                  RadToDeg(m.max_travel_rad), m.limiting_joint + 1, m.duration_s);
    out << line;
  }
  std::snprintf(line, sizeof(line), "%zu moves, %.1f s of motion at velocity scaling %.0f %%\n", moves.size(),
                total_motion_s, 100 * velocity_scaling);
  out << line;
  for (const std::string& line : check.scope) out << "checked: " << line << "\n";
  for (const std::string& p : problems) out << "REFUSED: " << p << "\n";
  return out.str();
}

}  // namespace selfcal::acquisition
