// The simulated robot: a `Robot` whose joints move in simulated (or real) time, with every fault a
// session must survive injectable by the count of calls (../shared/RELIABILITY.md R4-R10 and the fault-injecting
// mock robot of its "test infrastructure" section), and a log of every command for the F8 safety figures.
//
// Joint motion only, no kinematics: a move is a quintic time scaling from where the arm is to the target,
// timed so that the limiting joint peaks at its velocity limit times the scaling; after arrival every joint
// rings down (a damped sine) while GetStatus already says kIdle, as real arms do (R7). The state is
// evaluated lazily at clock.Now(), and the whole history is kept, so that JointsAt(t) gives the true joints
// at any past time (what the simulated camera renders from).
//
// Time is the robot's Clock: a SimulatedClock in tests and simulated sessions (deterministic, as fast as
// the computer allows), a MonotonicClock behind the network server (selfcal-robot-sim). Not thread-safe.
#pragma once

#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "robot/clock.h"
#include "robot/robot.h"

namespace selfcal::robot {

// Faults, each triggered by the 0-based index of a call: "move #k" is the k-th StartMove call and "read #n"
// the n-th ReadJoints call since construction, whatever their outcome (so move #k is the call after which
// counts().start_move == k + 1). The arm's reaction is described per field.
struct SimulatedRobotFaults {
  // R5: StartMove refuses the move with kRejected ("controller refused").
  std::set<int> reject_moves;
  // R6: the move is accepted and starts, but freezes half way (the arm halts at the midpoint); GetStatus
  // says kMoving forever, until Stop().
  std::set<int> hang_moves;
  // R9: half way the controller stops the arm; GetStatus says kProtectiveStop (kEmergencyStop) and every
  // later StartMove is rejected until AcknowledgeStop() (the person at the teach pendant).
  std::set<int> protective_stop_moves;
  std::set<int> emergency_stop_moves;
  // R10: half way the connection is lost and the arm halts where it is; every call returns kDisconnected
  // until Connect() is called again (behind RobotServer: the server closes the client's socket).
  std::set<int> disconnect_moves;
  // R4: once move k has settled (jog_delay_s after arrival, or when the next move is commanded if that
  // comes earlier) the arm is displaced by jog_offset_rad, as if someone had jogged it.
  std::set<int> jog_after_moves;
  Eigen::VectorXd jog_offset_rad;  // one entry per joint; empty: 0.02 rad on joint 0
  // Counted from the arm's true arrival (the end of the quintic), which precedes the moment a session
  // polls the status as idle. 0.5 s falls inside a simulated session's 0.6 s settle dwell; a delay between
  // its settle time and its next frame jogs between settle and capture (`selfcal run --fault-jog-delay-s`).
  double jog_delay_s = 0.5;
  // R7: the ring-down after move k decays 20 times slower (settle_tau_s * 20).
  std::set<int> slow_settle_moves;
  // R7: after move k the arm never comes to rest: every reading until the next move reports 0.05 rad/s on
  // every joint (the positions are the arm's), while GetStatus says idle at arrival.
  std::set<int> never_settle_moves;
  // R8: reading #n carries the previous reading's values and its timestamp minus 1 s (the first reading:
  // the current values, 1 s old).
  std::set<int> stale_reads;
  // R8: reading #n has NaN in joint 1 (0-based; the arm needs two joints).
  std::set<int> nan_reads;
  // R8: reading #n has one joint fewer (position and velocity).
  std::set<int> short_reads;
};

struct SimulatedRobotOptions {
  // model, serial ("" = "sim-<seed>") and calibration_id are reported as given; backend is always
  // "simulated" and real_hardware always false (R12).
  RobotIdentity identity{"simulated", "simulated-arm", "", "", false};
  JointLimits limits;                  // sizes define the number of joints
  Eigen::VectorXd initial_joints_rad;  // where the arm is at construction; within the limits
  double latency_s = 0.05;             // motion starts this long after StartMove accepted it
  double min_move_duration_s = 0.05;   // even a zero-length move takes this long
  // Ring-down after arrival, per joint: target + A exp(-t/tau) sin(2 pi f t), t since arrival.
  double settle_amplitude_rad = 2e-4;
  double settle_tau_s = 0.08;
  double settle_frequency_hz = 6;
  // The ring-down ends exactly (the arm is at its target) this long after arrival, scaled with tau for a
  // slow-settling move; infinity: it never ends. A finite cutoff shorter than a session's settle dwell
  // makes a restarted simulated arm indistinguishable from one that never stopped (resume tests).
  double ring_cutoff_s = std::numeric_limits<double>::infinity();
  double encoder_noise_rad = 0;  // std of Gaussian noise on ReadJoints positions (not on JointsAt)
  uint64_t seed = 0;             // the noise generator's seed
  SimulatedRobotFaults faults;

  int num_joints() const { return static_cast<int>(limits.lower_rad.size()); }
  // OK, or ErrorCode::kInvalidInput listing every bad field by name and value.
  Status Validate() const;
};

// Every call by kind, counted whatever its outcome (F8: "commands reaching the robot").
struct CommandCounts {
  int connect = 0;
  int disconnect = 0;
  int identity = 0;
  int limits = 0;
  int read = 0;
  int start_move = 0;
  int status = 0;
  int stop = 0;
};

// A move the robot accepted (F8: what was actually sent to the arm).
struct AcceptedMove {
  int index = -1;                 // move #k: the StartMove call count
  Eigen::VectorXd target_rad;
  double velocity_scaling = 1;
  double command_time_s = 0;      // when StartMove accepted it
  double start_time_s = 0;        // command time + latency: when the arm began to move
  double duration_s = 0;          // of the quintic profile, start to arrival
};

class SimulatedRobot : public Robot {
 public:
  // Throws InvalidArgument when options.Validate() fails (a caller error). `clock` must outlive the robot.
  SimulatedRobot(const SimulatedRobotOptions& options, Clock& clock);

  Status Connect() override;
  void Disconnect() override;
  Result<RobotIdentity> Identity() override;
  Result<JointLimits> Limits() override;
  Result<JointReading> ReadJoints() override;
  // kRejected, naming the joint, value and limit, when: the size differs from the joint count, a value is
  // not finite or outside the limits, the scaling is not in (0, 1], a move is still running, or a
  // protective/emergency stop is active. Also kRejected for an injected reject_moves fault.
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override;
  Result<RobotStatus> GetStatus() override;
  // Halts a running move where the arm is at Now(); the state becomes kIdle unless a protective or
  // emergency stop is active (those need AcknowledgeStop). The ring-down after an arrival is not motion
  // and is not affected.
  Status Stop() override;

  // The person at the teach pendant acknowledges a protective or emergency stop (R9); no effect otherwise.
  void AcknowledgeStop();

  // The true joints and joint velocities at time t on the robot's clock (at or after construction). For
  // t <= Now() this is the history as it happened (motion, ring-down, stops, jogs); later times give the
  // motion as planned so far.
  Eigen::VectorXd JointsAt(double t) const;
  Eigen::VectorXd JointVelocitiesAt(double t) const;

  // Duration of a quintic move from `from_rad` to `to_rad` at `velocity_scaling`: the limiting joint peaks
  // at max_velocity * scaling (peak ds/dtau of the quintic is 15/8), at least min_move_duration_s.
  double MoveDuration(const Eigen::VectorXd& from_rad, const Eigen::VectorXd& to_rad,
                      double velocity_scaling) const;

  const CommandCounts& counts() const { return counts_; }
  const std::vector<AcceptedMove>& accepted_moves() const { return accepted_moves_; }
  const SimulatedRobotOptions& options() const { return options_; }

 private:
  // One piece of the joint history, valid from t_begin until the next piece begins.
  struct Piece {
    enum class Kind { kRest, kQuintic };
    Kind kind = Kind::kRest;
    double t_begin = 0;
    Eigen::VectorXd from_rad;  // kQuintic: start joints
    Eigen::VectorXd to_rad;    // kRest: where the arm rests; kQuintic: target
    double duration_s = 0;     // kQuintic
    double ring_amplitude_rad = 0;  // kRest: ring-down after an arrival (0: none) ...
    double ring_tau_s = 1;
    double ring_start_s = 0;        // ... counted from the arrival
  };
  // What happens to the current move and when (all times on the clock).
  enum class MoveFault { kNone, kHang, kProtectiveStop, kEmergencyStop, kDisconnect };
  struct CurrentMove {
    int index = -1;
    MoveFault fault = MoveFault::kNone;
    double fault_time_s = 0;       // half way through the quintic
    double motion_end_s = 0;       // arrival, fault time or stop time; +inf while a hang lasts
    bool fault_fired = false;
  };

  // Brings the latched state (stop faults, lost connection) up to Now(); returns Now().
  double Advance();
  // kNotConnected / kDisconnected when the link is not up; OK otherwise.
  Status CheckLink(const char* call) const;
  const Piece& PieceAt(double t) const;
  double RingCutoff(const Piece& piece) const {
    return options_.ring_cutoff_s * piece.ring_tau_s / options_.settle_tau_s;
  }
  // Drops every piece that begins after t.
  void TruncateAfter(double t);
  bool Moving(double now) const;
  std::string Name() const;

  SimulatedRobotOptions options_;
  Clock& clock_;
  RobotIdentity identity_;
  std::vector<Piece> history_;
  CurrentMove move_;
  bool connected_ = false;
  bool link_lost_ = false;  // a disconnect fault fired; cleared by Connect()
  std::string link_lost_reason_;
  MotionState stop_state_ = MotionState::kIdle;  // kProtectiveStop / kEmergencyStop while latched
  std::string stop_message_;
  std::mt19937_64 rng_;
  bool have_last_reading_ = false;
  JointReading last_reading_;
  CommandCounts counts_;
  std::vector<AcceptedMove> accepted_moves_;
};

}  // namespace selfcal::robot
