// The robots driven through a vendor's own interface, for `selfcal run`: --backend ur (Universal Robots'
// RTDE, secondary interface and Dashboard server, docs/universal-robots.md) and --backend fanuc (FANUC's
// Remote Motion Interface, docs/fanuc.md); the confirmation, limits and port every run backend shares.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "app/session_command.h"
#include "base/status.h"
#include "kinematics/robot_model.h"
#include "robot/robot.h"

namespace selfcal::app {

// Typed confirmation before a real backend moves (R1): the preview printed (escaped), then for real hardware
// the operator types the robot's serial; a dry run is never armed, a simulated robot always.
bool ConfirmOnTerminal(const std::string& preview, const robot::RobotIdentity& identity, bool dry_run);

// The manual and network backends' joint limits: the nominal model's, a nominal velocity of 0.5 rad/s.
robot::JointLimits ManualJointLimits(const RobotModel& nominal);

// The port of --address HOST:PORT: 1-65535, else -1.
int PortNumber(const std::string& text);

// The robot of `a.robot_backend` ("ur" or "fanuc") at `a.address`, not connected, with the robot config's
// `position_limits`; `log` gets what it finds at connect. kInvalidInput naming the option.
Result<std::unique_ptr<robot::Robot>> MakeVendorRobot(const RunSettings& a, const robot::JointLimits& position_limits,
                                                      const std::function<void(const std::string&)>& log);

}  // namespace selfcal::app
