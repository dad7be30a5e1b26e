// Module robot (ARCHITECTURE.md): the Robot interface (this header: asynchronous moves, typed RobotError;
// clock.h: the session Clock); SimulatedRobot (quintic moves, ring-down, fault injection R4-R10, command
// counts); the network line protocol (NetworkRobot, RobotServer; docs/robot-protocol.md); the manual backend;
// Universal Robots natively (ur_robot.h, UrRobot: RTDE readings, movej/stopj on the secondary interface, the
// Dashboard's checks and the factory kinematics at connect; the byte formats in ur_protocol.h; ur_fake.h, the
// loopback fake UrFakeController; docs/universal-robots.md). Uses base.
//
// The robot interface (../shared/DESIGN.md section 2, layer 2): what a calibration session needs from an arm, and
// nothing else. Backends: the simulated robot (simulated_robot.h), the network line protocol
// (network_robot.h, docs/robot-protocol.md; robot_server.h serves any Robot with it) and the manual
// backend (manual_robot.h).
//
// Motion is asynchronous: StartMove returns once the controller accepted (or refused) the target, and the
// caller polls GetStatus while it tracks dots, runs its watchdog (../shared/RELIABILITY.md R6) and watches for a
// stop request (R11). Backends never retry, resume or re-send a move by themselves (R9).
//
// Time: every timestamp is seconds on the session's Clock (clock.h). Live backends stamp readings with
// the monotonic clock when they arrive (the clock V4L2 stamps frames with), the simulated robot with the
// simulated clock it shares with the simulated camera.
//
// Errors: every failure is a Status with ErrorCode kHardware whose detail (domain kRobotErrorDomain)
// carries a RobotError; RobotErrorOf() reads it back. Messages name the backend and the pose or joint.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "base/status.h"

namespace selfcal::robot {

enum class RobotError {
  kNone = 0,
  kNotConnected,     // Connect() not called or failed
  kRejected,         // the controller refused the move (out of reach, limits, not ready) [R5]
  kTimeout,          // a reply or a motion did not come in time [R6]
  kProtectiveStop,   // the controller stopped the arm (collision, limit) [R9]
  kEmergencyStop,    // E-stop pressed [R9]
  kDisconnected,     // the connection broke [R10]
  kBadReading,       // joint reading stale, incomplete, non-finite [R8]
  kProtocol,         // the backend answered something the protocol does not allow
  kOperatorAbort,    // manual backend: the operator declined
};

inline constexpr const char* kRobotErrorDomain = "robot";

// "rejected", "protective_stop", ...: stable names for journals and reports.
const char* RobotErrorName(RobotError error);

// A Status with ErrorCode::kHardware carrying `error` (kNone is not allowed) and `message`.
Status RobotFailure(RobotError error, const std::string& message);

// The RobotError of a Status: kNone for OK and for errors without a robot detail.
RobotError RobotErrorOf(const Status& status);

struct RobotIdentity {
  std::string backend;         // "simulated", "network", "manual"
  std::string model;           // e.g. "puma560"
  std::string serial;          // the controller's serial or "sim-<seed>"
  std::string calibration_id;  // the controller's own calibration/version id (R13), "" if none
  bool real_hardware = false;  // true when commands can move a physical arm (R12)
};

// The refusal of a controller at connect ("" when none): `now` differs from `first` (the identity of the
// first connect, a reconnect to another arm, R13) in any field, or from `expected` in a non-empty field
// (R12). Names both identities; `name` prefixes the message.
std::string IdentityRefusal(const RobotIdentity& now, const std::optional<RobotIdentity>& first,
                            const std::optional<RobotIdentity>& expected, const std::string& name);

struct JointLimits {
  Eigen::VectorXd lower_rad;
  Eigen::VectorXd upper_rad;
  Eigen::VectorXd max_velocity_rad_s;  // at velocity scaling 1
};

struct JointReading {
  Eigen::VectorXd position_rad;
  Eigen::VectorXd velocity_rad_s;  // same size as position; zeros when the backend cannot tell
  double time_s = 0;               // when the joints had these values, on the session clock
};

enum class MotionState {
  kIdle = 0,         // not moving; the last move (if any) finished
  kMoving,
  kProtectiveStop,   // stopped by the controller; needs a person [R9]
  kEmergencyStop,    // E-stop; needs a person [R9]
  kFault,            // any other controller fault
};
const char* MotionStateName(MotionState state);

// Why `limits` cannot describe an arm ("" when they can): sizes differ or are zero, a value is not
// finite, lower >= upper, or a velocity limit is not positive. Names the joint (1-based) and the value.
std::string CheckJointLimits(const JointLimits& limits);

// The joint-space profile every backend here assumes: the quintic time scaling
// s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, whose peak rate ds/dtau is 15/8.
inline constexpr double kQuinticPeakRate = 1.875;

// Duration of a quintic move from `from_rad` to `to_rad` when the limiting joint peaks at its velocity
// limit times `velocity_scaling`; *limiting_joint (optional) receives that joint (-1 for a null move).
// The simulated robot moves this way; the session's preflight and watchdog time moves with it.
double QuinticMoveDuration(const Eigen::VectorXd& from_rad, const Eigen::VectorXd& to_rad,
                           const Eigen::VectorXd& max_velocity_rad_s, double velocity_scaling,
                           int* limiting_joint = nullptr);

// Why `target_rad` at `velocity_scaling` cannot be commanded to an arm with `limits` ("" when it can):
// the size differs from the joint count, a value is not finite or outside its limits, or the scaling is
// not in (0, 1]. Names the joint (1-based), the value and the limit, in rad. For the backends that check
// targets themselves before anything moves (R3, C6).
std::string CheckMoveTarget(const JointLimits& limits, const Eigen::VectorXd& target_rad, double velocity_scaling);

// What a backend checks of the arm before anything moves (R8, R4): two readings of `read` taken
// interval_s apart, each of the limits' length, finite and within them, agreeing within tolerance_rad with
// joint speeds within velocity_rad_s (at rest). `sleep` waits the interval; `name` prefixes the messages.
// kBadReading naming the joint and values, or the error of `read`.
struct RestCheck {
  double interval_s = 0.05;
  double tolerance_rad = 1e-3;
  double velocity_rad_s = 1e-2;
};
Status CheckStartAtRest(const std::function<Result<JointReading>()>& read, const std::function<void(double)>& sleep,
                        const JointLimits& limits, const RestCheck& rest, const std::string& name);

struct RobotStatus {
  MotionState state = MotionState::kIdle;
  std::string message;  // the controller's words, if any
};

// Not thread-safe: one caller drives a robot.
class Robot {
 public:
  virtual ~Robot() = default;

  virtual Status Connect() = 0;
  virtual void Disconnect() = 0;

  virtual Result<RobotIdentity> Identity() = 0;
  virtual Result<JointLimits> Limits() = 0;

  // The current joint state. A backend returns what it got; validating freshness, completeness and
  // finiteness is the caller's job (R8), so that faults are counted in one place.
  virtual Result<JointReading> ReadJoints() = 0;

  // Starts a joint-space move to `target_rad` at `velocity_scaling` in (0, 1] of the joint velocity
  // limits. Returns once the controller accepted it; kRejected when refused. Does not wait for arrival.
  virtual Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) = 0;

  virtual Result<RobotStatus> GetStatus() = 0;

  // Stops any motion now. Safe to call in any state, repeatedly.
  virtual Status Stop() = 0;
};

}  // namespace selfcal::robot
