// The Universal Robots backend (`selfcal run --backend ur --address HOST`, docs/universal-robots.md): a
// `Robot` that speaks a UR controller's own interfaces (ur_protocol.h), no program on the robot's side:
//   - RTDE (30004): the joints, joint speeds, runtime state, safety and robot status bits, streamed at
//     rtde_frequency_hz and read as it comes by a thread of this object; every reading is the newest
//     package, stamped on this process's CLOCK_MONOTONIC when it arrived (as network_robot.h's readings,
//     for the camera's freshness checks);
//   - the secondary interface (30002): `movej` to move, `stopj` to stop; its robot state stream read at
//     connect for the kinematics info (the factory calibration: DH values and checksums), then drained;
//   - the Dashboard server (29999): at connect, what a person must clear before anything moves (remote
//     control off, a protective or emergency stop, the arm not running), the model and serial; and a
//     second way to stop (`stop`) when stopj cannot be sent.
// Connect() checks all of it, and the start reading at rest within the robot config's limits, before
// anything is sent to the arm: a refusal at connect sends no script at all. A move is done when every
// joint speed is below settled_velocity_rad_s (the network backend's at-rest speed) and every joint lies
// within target_tolerance_rad of the target. A lost connection on any of the three ports is kDisconnected
// on every later call until Connect() succeeds again (R10), and a reconnect refuses another arm (R13).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "base/status.h"
#include "robot/clock.h"
#include "robot/line_socket.h"
#include "robot/robot.h"
#include "robot/ur_protocol.h"

namespace selfcal::robot {

struct UrRobotOptions {
  int rtde_port = ur::kRtdePort;
  int secondary_port = ur::kSecondaryPort;
  int dashboard_port = ur::kDashboardPort;
  double connect_timeout_s = 2.0;
  double reply_timeout_s = 1.0;
  double rtde_frequency_hz = 125;
  // The robot config's joint position limits and the joint speed limits (required): UR's interfaces do not
  // report the limits, so the config's are checked here before a move is sent.
  JointLimits limits;
  RestCheck rest;  // the start reading at rest (robot.h); rest.velocity_rad_s is also the settled speed
  double target_tolerance_rad = 1e-3;
  // movej's acceleration as this many times its velocity (1/s): the trapezoid's ramps then take at most
  // 1/this seconds beyond the quintic duration the session's watchdog allows (robot.h).
  double acceleration_per_velocity = 4.0;
  double stop_deceleration_rad_s2 = 3.0;  // stopj's
  std::optional<RobotIdentity> expected_identity;  // refused at connect when a non-empty field differs
  std::function<void(const std::string&)> log;     // what Connect() found (the factory calibration); may be empty
  Status Validate() const;
};

// The joint speed limit assumed for every joint of a UR arm: 120 deg/s, the slowest joint of UR's
// datasheets (the base and shoulder of the larger arms); the velocity scaling is a fraction of it.
inline constexpr double kUrJointSpeedLimit_rad_s = 2.0943951023931953;

// The options of `selfcal run --backend ur`: `host` a host name or address (empty, or HOST:PORT, refused:
// the ports are UR's), `ports` none (a controller's) or the RTDE, secondary and Dashboard ports (the
// loopback fake's), the robot config's position limits with kUrJointSpeedLimit_rad_s. kInvalidInput
// naming the option.
Result<UrRobotOptions> UrRunOptions(const std::string& host, const std::vector<int>& ports, JointLimits position_limits);

class UrRobot : public Robot {
 public:
  // Does not connect. Throws InvalidArgument on invalid options (a caller error).
  UrRobot(std::string host, UrRobotOptions options);
  ~UrRobot() override;

  Status Connect() override;
  void Disconnect() override;
  // backend "ur", the Dashboard's model and serial, the kinematics checksums as calibration id
  // (ur::CalibrationIdOf), real hardware.
  Result<RobotIdentity> Identity() override;
  Result<JointLimits> Limits() override;
  Result<JointReading> ReadJoints() override;
  // Checks the target (CheckMoveTarget) and the arm's state before sending; kRejected sends nothing.
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override;
  Result<RobotStatus> GetStatus() override;
  // stopj on the secondary interface; when that cannot be sent, the Dashboard's `stop`.
  Status Stop() override;

  // The factory calibration read at connect (the kinematics info), nullopt before.
  const std::optional<ur::KinematicsInfo>& factory_kinematics() const { return kinematics_; }
  const std::string& name() const { return name_; }
  // RTDE data packages read since the object was made (the reader thread's progress).
  uint64_t packages_read() {
    std::lock_guard<std::mutex> lock(mutex_);
    return packages_read_;
  }

 private:
  Status ConnectUnchecked();
  Status CheckDashboard();
  Status ReadKinematics();
  Status StartRtde();
  // One package from the RTDE socket (no change of the link state): kTimeout when none began in time.
  Result<ur::RtdePackage> ReadRtdePackage(double timeout_s);
  // The reader thread: from the end of Connect() until CloseAll(), the RTDE packages and the secondary
  // interface's stream are read as they arrive (a stream left unread while the operator reads the preview
  // would fill the socket, and a controller may drop such a client); the newest state kept with its
  // arrival time; the first failure kept for the caller.
  void StartReader();
  void ReadStreams();
  // The newest state package, no older than reply_timeout_s and arrived at or after not_before_s (waiting
  // up to reply_timeout_s for one), and when it arrived; the reader's failure breaks the link.
  Result<ur::UrState> LatestState(double* arrival_s = nullptr,
                                  double not_before_s = -std::numeric_limits<double>::infinity());
  Result<std::string> Dashboard(const std::string& command);
  Status LinkStatus(const char* call) const;
  Status Broken(RobotError error, const std::string& reason);
  void CloseAll();

  std::string host_;
  UrRobotOptions options_;
  std::string name_;
  MonotonicClock clock_;
  LineSocket rtde_, secondary_, dashboard_;
  enum class Link { kNeverConnected, kUp, kBroken, kClosed } link_ = Link::kNeverConnected;
  std::string broken_reason_;
  uint8_t recipe_id_ = 0;
  RobotIdentity identity_;
  std::optional<RobotIdentity> first_identity_;
  std::optional<ur::KinematicsInfo> kinematics_;
  std::optional<Eigen::VectorXd> target_;  // the move in progress
  ur::UrState last_state_;
  std::thread reader_;
  std::atomic<bool> stop_reader_{true};
  std::mutex mutex_;  // guards the four below, written by the reader thread
  std::optional<ur::UrState> latest_;
  double latest_s_ = 0;
  Status reader_failure_;
  uint64_t packages_read_ = 0;
};

}  // namespace selfcal::robot
