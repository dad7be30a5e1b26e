// The network robot: a `Robot` that talks the selfcal line protocol (docs/robot-protocol.md) over TCP to
// a small server beside the robot's controller (robot_server.h serves any Robot; selfcal-robot-sim serves
// the simulated one).
//
// Every request waits at most reply_timeout_s for its reply, on a non-blocking socket with poll(). The
// connection's failure modes map to RobotErrors:
//   - no reply in time -> kTimeout, and the connection is closed (a late reply would otherwise be taken for
//     the answer to the next request); every later call -> kDisconnected until Connect() succeeds again;
//   - connection closed or reset -> kDisconnected, likewise until Connect() succeeds again (R10);
//   - a line the protocol does not allow -> kProtocol quoting the line (a line over max_line_bytes also
//     closes the connection);
//   - `ERR <code>` replies -> the error the code names (line_protocol.h).
// Text from the controller (identity, ERR texts, quoted lines) reaches messages sanitised by
// base/terminal_text.h's TerminalSafe: control characters (NUL, ESC of the ANSI sequences, CR, BEL, DEL,
// the C1 controls) and invalid UTF-8 are written as \xNN (\u00NN), printable UTF-8 is kept.
// A reconnect re-checks the controller's identity against the one seen at the first connection and
// refuses a different arm with kProtocol (R10, R13), before anything else is sent.
//
// Timestamps: a reading is stamped with this process's CLOCK_MONOTONIC when its reply arrives, not with
// the controller's clock: the camera's frames are stamped on CLOCK_MONOTONIC, and the freshness checks
// (R7, R8, V5) compare the two, which needs one clock. The error is at most one round trip (sub-ms on a
// LAN). The controller's own time is kept in last_controller_time_s() for logs.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "base/status.h"
#include "robot/clock.h"
#include "robot/line_protocol.h"
#include "robot/line_socket.h"
#include "robot/robot.h"

namespace selfcal::robot {

struct NetworkRobotOptions {
  double connect_timeout_s = 2.0;
  double reply_timeout_s = 1.0;
  // When set, Connect() refuses (kProtocol) a controller whose model, serial or calibration id differ from
  // the non-empty fields here (R12, R13).
  std::optional<RobotIdentity> expected_identity;
  size_t max_line_bytes = protocol::kMaxLineBytes;
  // The robot config's joint position limits (lower_rad, upper_rad; max_velocity_rad_s unused). When set,
  // Connect() checks everything a session checks later, before anything moves: the joint count in HELLO,
  // LIMITS and JOINTS against the config's; the controller's limits intersected with the config's (the
  // narrower bound wins per joint, and `log` says which joints were narrowed; an empty intersection is
  // refused); and the start reading: two readings rest_interval_s apart, each of the config's length,
  // finite and within the limits, agreeing within rest_tolerance_rad with velocities within
  // rest_velocity_rad_s (at rest). A refusal at connect sends nothing to the arm (no MOVE, no STOP).
  std::optional<JointLimits> config_limits;
  double rest_interval_s = 0.05;
  double rest_tolerance_rad = 1e-3;
  double rest_velocity_rad_s = 1e-2;
  // Where Connect() reports what it adapted (the narrowed limits); may be empty.
  std::function<void(const std::string&)> log;
  // OK, or ErrorCode::kInvalidInput naming the bad field.
  Status Validate() const;
};

class NetworkRobot : public Robot {
 public:
  // Does not connect. Throws InvalidArgument on invalid options (a caller error).
  NetworkRobot(std::string host, int port, NetworkRobotOptions options = {});
  ~NetworkRobot() override;

  // Opens the connection, says HELLO, checks the identity (above) and fetches the limits. A no-op while
  // connected. kNotConnected / kTimeout when the server cannot be reached; kProtocol for a wrong protocol,
  // version or identity.
  Status Connect() override;
  // Says BYE (best effort) and closes. Later calls return kNotConnected.
  void Disconnect() override;
  // The identity from HELLO, backend "network" (no request).
  Result<RobotIdentity> Identity() override;
  Result<JointLimits> Limits() override;
  Result<JointReading> ReadJoints() override;
  // Checks the target against the limits fetched at Connect (size, finite, within limits, scaling in
  // (0, 1]) and refuses with kRejected without sending anything; then MOVE. OK once the controller
  // accepted the move, not at arrival.
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override;
  Result<RobotStatus> GetStatus() override;
  Status Stop() override;

  // "network robot host:port", the prefix of every message.
  const std::string& name() const { return name_; }
  // The controller's timestamp of the last reading (its own clock, s); NaN before the first.
  double last_controller_time_s() const { return last_controller_time_s_; }

 private:
  enum class Link { kNeverConnected, kUp, kBroken, kClosed };

  Status LinkStatus(const char* call) const;
  // Sends `request` and returns the reply line, managing the link state on transport failures.
  Result<std::string> RoundTrip(protocol::RequestKind kind, const std::string& request);
  // Closes the socket and marks the link broken with `reason`.
  void Break(const std::string& reason);
  // HELLO and LIMITS on a fresh socket; the identity checks.
  Status Handshake();
  Status HandshakeUnsanitised();
  // With config_limits: the joint count, the intersection of the limits, and the start reading at rest.
  Status CheckAgainstConfig(const protocol::HelloInfo& hello, JointLimits* limits);
  Status CheckStartReading();

  std::string host_;
  int port_;
  NetworkRobotOptions options_;
  std::string name_;
  MonotonicClock clock_;
  LineSocket socket_;
  Link link_ = Link::kNeverConnected;
  std::string broken_reason_;
  std::optional<protocol::HelloInfo> first_hello_;
  protocol::HelloInfo hello_;
  JointLimits limits_;
  double last_controller_time_s_;
};

}  // namespace selfcal::robot
