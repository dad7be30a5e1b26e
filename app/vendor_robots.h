// The robots driven through a vendor's own interface, for `selfcal run`: --robot ur (Universal Robots'
// RTDE, secondary interface and Dashboard server, docs/universal-robots.md) and --robot fanuc (FANUC's
// Remote Motion Interface, docs/fanuc.md).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "app/session_command.h"
#include "base/status.h"
#include "robot/robot.h"

namespace selfcal::app {

// The robot of `a.robot_backend` ("ur" or "fanuc") at `a.address`, not connected, with the robot config's
// `position_limits`; `log` gets what it finds at connect. kInvalidInput naming the option.
Result<std::unique_ptr<robot::Robot>> MakeVendorRobot(const RunSettings& a, const robot::JointLimits& position_limits,
                                                      const std::function<void(const std::string&)>& log);

}  // namespace selfcal::app
