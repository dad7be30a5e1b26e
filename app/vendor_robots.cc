#include "app/vendor_robots.h"

#include <algorithm>
#include <iostream>
#include <utility>

#include "app/cli_output.h"
#include "base/terminal_text.h"

#include "robot/fanuc_robot.h"
#include "robot/ur_robot.h"

namespace selfcal::app {

// Typed confirmation before a real backend moves (R1): the operator types the robot's serial. The
// preview holds the controller's identity text: printed escaped. With --json it goes to stderr, stdout
// being the document's.
bool ConfirmOnTerminal(const std::string& preview, const robot::RobotIdentity& identity, bool dry_run) {
  std::ostream& out = JsonMode() ? std::cerr : std::cout;
  ClearProgressLine();
  out << TerminalSafe(preview);
  if (dry_run) {
    out << "dry run: nothing moved, no command was sent to the robot\n";
    return false;
  }
  if (!identity.real_hardware) {
    out << "simulated robot: armed without confirmation\n";
    return true;
  }
  out << "This moves a REAL robot (" << TerminalSafe(identity.model) << ", serial " << TerminalSafe(identity.serial)
      << "). Type the serial to arm, anything else to cancel: " << std::flush;
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return answer == identity.serial;
}

// The manual backend's joint limits: the nominal model's, a nominal velocity (the operator moves; timing only).
robot::JointLimits ManualJointLimits(const RobotModel& nominal) {
  robot::JointLimits limits;
  const int n = nominal.num_joints();
  limits.lower_rad.resize(n);
  limits.upper_rad.resize(n);
  for (int j = 0; j < n; ++j) {
    limits.lower_rad[j] = nominal.limits[j].min_rad;
    limits.upper_rad[j] = nominal.limits[j].max_rad;
  }
  limits.max_velocity_rad_s = Eigen::VectorXd::Constant(n, 0.5);
  return limits;
}

// The port of --address HOST:PORT: 1-65535, else -1.
int PortNumber(const std::string& text) {
  if (text.empty() || text.size() > 5 || !std::all_of(text.begin(), text.end(), ::isdigit)) return -1;
  const int port = std::stoi(text);
  return port >= 1 && port <= 65535 ? port : -1;
}

Result<std::unique_ptr<robot::Robot>> MakeVendorRobot(const RunSettings& a, const robot::JointLimits& position_limits,
                                                      const std::function<void(const std::string&)>& log) {
  if (a.address == RunSettings().address) {
    return Status::Error(ErrorCode::kInvalidInput,
                         a.robot_backend == "ur"
                             ? "--backend ur needs --address HOST, the controller's (docs/universal-robots.md)"
                             : "--backend fanuc needs --address HOST[:PORT], the controller's (docs/fanuc.md)");
  }
  if (a.robot_backend == "ur") {
    Result<robot::UrRobotOptions> ur = robot::UrRunOptions(a.address, a.ur_ports, position_limits);
    if (!ur.ok()) return ur.status();
    ur.value().log = log;
    return std::unique_ptr<robot::Robot>(std::make_unique<robot::UrRobot>(a.address, *ur));
  }
  if (!a.ur_ports.empty()) return Status::Error(ErrorCode::kInvalidInput, "--ur-ports applies to --backend ur only");
  std::string host;
  Result<robot::FanucRobotOptions> fanuc = robot::FanucRunOptions(a.address, position_limits, &host);
  if (!fanuc.ok()) return fanuc.status();
  fanuc.value().log = log;
  return std::unique_ptr<robot::Robot>(std::make_unique<robot::FanucRobot>(host, *fanuc));
}

}  // namespace selfcal::app
