// One pose of a measurement plan: what the session loop drives the robot to (acquisition/session_runner.h,
// its preflight in acquisition/motion_safety.h) and what a session's pose_planned record holds
// (docs/session-format.md). The one type for both, in the lowest module that needs it.
#pragma once

#include <string>

#include <Eigen/Core>

#include "observations/observation_set.h"

namespace selfcal::session {

struct PlannedPose {
  std::string id;  // e.g. "p00", unique in the plan
  PoseRole role = PoseRole::kIdentification;
  Eigen::VectorXd joints_rad;
};

}  // namespace selfcal::session
