// The FANUC backend (`selfcal run --backend fanuc --address HOST[:PORT]`, docs/fanuc.md): a `Robot` that
// speaks FANUC's Remote Motion Interface (fanuc_protocol.h), the controller's RMI option, no program of
// ours on the robot's side. One TCP connection: FRC_Connect on the connect port (16001) names the port
// of the session; on it every call is a command and its answer (FRC_GetStatus, FRC_ReadJointAngles,
// FRC_Abort), and a move is the instruction FRC_JointMotionJRep with a sequence id, whose answer the
// controller sends when the instruction has run.
// Connect() checks, before anything is sent that could move the arm: the teach pendant is disabled, the
// servos are ready, no program runs, the identity (and a reconnect's: the same controller), the start
// reading at rest within the robot config's limits. FRC_Initialize is sent before the first move, so that a
// refusal or a dry run leaves the controller's RMI as it was. selfcal never sends FRC_Reset: clearing an alarm is a person's act at the pendant.
// A move is done when its instruction was answered without error and every joint lies within
// target_tolerance_rad of the target. Stop() is FRC_Abort (on a fresh connection when the link is lost), Ok
// only once the controller answered it with ErrorID 0.
// A lost connection, FRC_Terminate or a wrong answer is kDisconnected/kProtocol on every later call until
// Connect() succeeds again (R10); FRC_SystemFault makes every later status a fault and refuses moves.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "base/status.h"
#include "robot/clock.h"
#include "robot/fanuc_protocol.h"
#include "robot/line_socket.h"
#include "robot/robot.h"

namespace selfcal::robot {

struct FanucRobotOptions {
  int connect_port = fanuc::kConnectPort;
  double connect_timeout_s = 2.0;
  double reply_timeout_s = 1.0;
  // The robot config's joint position limits and the joint speed limits (required): RMI does not report
  // them, so the config's are checked here before a move is sent.
  JointLimits limits;
  RestCheck rest;  // the start reading at rest (robot.h)
  double target_tolerance_rad = 1e-3;
  std::optional<RobotIdentity> expected_identity;  // refused at connect when a non-empty field differs
  std::function<void(const std::string&)> log;     // what Connect() found; may be empty
  Status Validate() const;
};

// The joint speed assumed for every joint at Speed 100 % of a joint move: 60 deg/s, below the slowest
// joint of FANUC's small and mid-size arms' datasheets, so that the session's watchdog allows a move at
// least the time it takes; the velocity scaling is the percentage sent.
inline constexpr double kFanucJointSpeedLimit_rad_s = 1.0471975511965976;

// The options of `selfcal run --backend fanuc`: `address` HOST or HOST:PORT (the connect port, 16001 by
// default; another for the loopback fake), *host receives HOST; the robot config's position limits with
// kFanucJointSpeedLimit_rad_s. kInvalidInput naming the option.
Result<FanucRobotOptions> FanucRunOptions(const std::string& address, JointLimits position_limits, std::string* host);

class FanucRobot : public Robot {
 public:
  // Does not connect. Throws InvalidArgument on invalid options (a caller error).
  FanucRobot(std::string host, FanucRobotOptions options);
  ~FanucRobot() override;

  Status Connect() override;
  void Disconnect() override;
  // backend "fanuc"; model "FANUC RMI <major>.<minor>" (FRC_Connect's versions); serial the controller's
  // HOST:PORT (RMI reports no serial number); no calibration id (RMI reports no mastering data); real hardware.
  Result<RobotIdentity> Identity() override;
  Result<JointLimits> Limits() override;
  // FRC_ReadJointAngles; the speed is the difference of the last two readings (RMI reports none).
  Result<JointReading> ReadJoints() override;
  // Checks the target (CheckMoveTarget), the controller's status and that no move is pending before
  // sending; kRejected sends nothing.
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override;
  Result<RobotStatus> GetStatus() override;
  // FRC_Abort; on a fresh connection when the link is lost.
  Status Stop() override;

  const std::string& name() const { return name_; }

 private:
  Status ConnectUnchecked();
  Status CheckIdentity();
  // FRC_Initialize (RMI's program started on the controller), sent before the first move.
  Status Initialize();
  // FRC_Connect on the connect port: its answer (with the session's port).
  Result<fanuc::Packet> SessionPort();
  // Sends `request` and reads packets until the answer named `name` (of `kind`); instruction answers and
  // unsolicited packets on the way are noted (Note). A lost link, FRC_Terminate or a wrong answer breaks it.
  Result<fanuc::Packet> Ask(fanuc::PacketKind kind, const std::string& name, const std::string& request);
  Status Note(const fanuc::Packet& packet);
  // Reads the answer to an FRC_Abort just sent on `socket` (a fresh session): Ok for ErrorID 0; no answer
  // within the reply timeout, or another ErrorID, fails with a sentence saying the abort was sent.
  Status AbortAnswer(LineSocket* socket);
  Result<fanuc::ControllerStatus> ControllerState();
  Status LinkStatus(const char* call) const;
  Status Broken(RobotError error, const std::string& reason);
  void Close();

  std::string host_;
  FanucRobotOptions options_;
  std::string name_;
  MonotonicClock clock_;
  LineSocket socket_;
  int session_port_ = 0;
  enum class Link { kNeverConnected, kUp, kBroken, kClosed } link_ = Link::kNeverConnected;
  std::string broken_reason_;
  RobotIdentity identity_;
  std::optional<RobotIdentity> first_identity_;
  bool initialized_ = false;
  int next_sequence_id_ = 1;
  std::optional<int> pending_sequence_;  // the move in progress
  bool pending_answered_ = false;
  int pending_error_ = 0;
  std::optional<Eigen::VectorXd> target_;
  std::string system_fault_;  // FRC_SystemFault received: every later status is a fault
  std::optional<JointReading> last_reading_;
};

}  // namespace selfcal::robot
