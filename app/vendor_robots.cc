#include "app/vendor_robots.h"

#include <utility>

#include "robot/fanuc_robot.h"
#include "robot/ur_robot.h"

namespace selfcal::app {

Result<std::unique_ptr<robot::Robot>> MakeVendorRobot(const RunSettings& a, const robot::JointLimits& position_limits,
                                                      const std::function<void(const std::string&)>& log) {
  if (a.address == RunSettings().address) {
    return Status::Error(ErrorCode::kInvalidInput,
                         a.robot_backend == "ur"
                             ? "--robot ur needs --address HOST, the controller's (docs/universal-robots.md)"
                             : "--robot fanuc needs --address HOST[:PORT], the controller's (docs/fanuc.md)");
  }
  if (a.robot_backend == "ur") {
    Result<robot::UrRobotOptions> ur = robot::UrRunOptions(a.address, a.ur_ports, position_limits);
    if (!ur.ok()) return ur.status();
    ur.value().log = log;
    return std::unique_ptr<robot::Robot>(std::make_unique<robot::UrRobot>(a.address, *ur));
  }
  if (!a.ur_ports.empty()) return Status::Error(ErrorCode::kInvalidInput, "--ur-ports applies to --robot ur only");
  std::string host;
  Result<robot::FanucRobotOptions> fanuc = robot::FanucRunOptions(a.address, position_limits, &host);
  if (!fanuc.ok()) return fanuc.status();
  fanuc.value().log = log;
  return std::unique_ptr<robot::Robot>(std::make_unique<robot::FanucRobot>(host, *fanuc));
}

}  // namespace selfcal::app
