#include "robot/simulated_robot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "base/numbers.h"

namespace selfcal::robot {
namespace {

constexpr double kNeverSettledVelocity_rad_s = 0.05;  // R7 fault: what the restless arm reads on every joint
constexpr double kSlowSettleFactor = 20;  // R7 fault: the ring-down's time constant times this
constexpr double kStaleAge_s = 1;         // R8 fault: a stale reading is this much older than the last

double QuinticS(double tau) { return tau * tau * tau * (10 - 15 * tau + 6 * tau * tau); }
double QuinticRate(double tau) { return 30 * tau * tau * (1 - 2 * tau + tau * tau); }

bool Has(const std::set<int>& indices, int index) { return indices.count(index) > 0; }

void CheckIndices(const char* field, const std::set<int>& indices, std::vector<std::string>* problems) {
  if (!indices.empty() && *indices.begin() < 0) {
    problems->push_back(std::string("faults.") + field + ": index " + std::to_string(*indices.begin()) +
                        " is negative (calls are counted from 0)");
  }
}

void CheckPositive(const char* field, double value, bool zero_allowed, std::vector<std::string>* problems) {
  if (!std::isfinite(value) || value < 0 || (!zero_allowed && value == 0)) {
    std::ostringstream problem;
    problem << field << " = " << value << " must be " << (zero_allowed ? "finite and >= 0" : "finite and > 0");
    problems->push_back(problem.str());
  }
}

}  // namespace

Status SimulatedRobotOptions::Validate() const {
  std::vector<std::string> problems;
  const std::string limits_problem = CheckJointLimits(limits);
  if (!limits_problem.empty()) {
    problems.push_back("limits: " + limits_problem);
  } else {
    // A target check is the same question as "may the arm be here".
    const std::string initial_problem = CheckMoveTarget(limits, initial_joints_rad, 1.0);
    if (!initial_problem.empty()) problems.push_back("initial_joints_rad: " + initial_problem);
    if (faults.jog_offset_rad.size() != 0 && faults.jog_offset_rad.size() != limits.lower_rad.size()) {
      problems.push_back("faults.jog_offset_rad: " + std::to_string(faults.jog_offset_rad.size()) +
                         " entries for " + std::to_string(limits.lower_rad.size()) + " joints");
    }
    if (!faults.nan_reads.empty() && num_joints() < 2) {
      problems.push_back("faults.nan_reads: needs at least 2 joints (the NaN goes into joint 1, 0-based)");
    }
  }
  if (faults.jog_offset_rad.size() != 0 && !faults.jog_offset_rad.allFinite()) {
    problems.push_back("faults.jog_offset_rad: not finite");
  }
  CheckPositive("latency_s", latency_s, true, &problems);
  CheckPositive("min_move_duration_s", min_move_duration_s, false, &problems);
  CheckPositive("settle_amplitude_rad", settle_amplitude_rad, true, &problems);
  CheckPositive("settle_tau_s", settle_tau_s, false, &problems);
  CheckPositive("settle_frequency_hz", settle_frequency_hz, true, &problems);
  CheckPositive("encoder_noise_rad", encoder_noise_rad, true, &problems);
  CheckPositive("faults.jog_delay_s", faults.jog_delay_s, true, &problems);
  CheckIndices("reject_moves", faults.reject_moves, &problems);
  CheckIndices("hang_moves", faults.hang_moves, &problems);
  CheckIndices("protective_stop_moves", faults.protective_stop_moves, &problems);
  CheckIndices("emergency_stop_moves", faults.emergency_stop_moves, &problems);
  CheckIndices("disconnect_moves", faults.disconnect_moves, &problems);
  CheckIndices("jog_after_moves", faults.jog_after_moves, &problems);
  CheckIndices("slow_settle_moves", faults.slow_settle_moves, &problems);
  CheckIndices("never_settle_moves", faults.never_settle_moves, &problems);
  CheckIndices("stale_reads", faults.stale_reads, &problems);
  CheckIndices("nan_reads", faults.nan_reads, &problems);
  CheckIndices("short_reads", faults.short_reads, &problems);
  if (problems.empty()) return Status::Ok();
  std::string message = "simulated robot options:";
  for (const std::string& problem : problems) message += "\n  " + problem;
  return Status::Error(ErrorCode::kInvalidInput, message);
}

SimulatedRobot::SimulatedRobot(const SimulatedRobotOptions& options, Clock& clock)
    : options_(options), clock_(clock), rng_(options.seed) {
  const Status valid = options_.Validate();
  SELFCAL_CHECK(valid.ok(), valid.message());
  identity_ = options_.identity;
  identity_.backend = "simulated";
  identity_.real_hardware = false;
  if (identity_.serial.empty()) identity_.serial = "sim-" + std::to_string(options_.seed);
  if (options_.faults.jog_offset_rad.size() == 0) {
    options_.faults.jog_offset_rad = Eigen::VectorXd::Zero(options_.num_joints());
    options_.faults.jog_offset_rad[0] = 0.02;
  }
  Piece initial;
  initial.t_begin = clock_.Now();
  initial.to_rad = options_.initial_joints_rad;
  history_.push_back(initial);
  move_.motion_end_s = initial.t_begin;
}

std::string SimulatedRobot::Name() const { return "simulated robot " + identity_.serial; }

double SimulatedRobot::Advance() {
  const double now = clock_.Now();
  if (move_.fault != MoveFault::kNone && !move_.fault_fired && now >= move_.fault_time_s) {
    move_.fault_fired = true;
    const std::string where = "during move #" + std::to_string(move_.index) + " (injected fault)";
    switch (move_.fault) {
      case MoveFault::kProtectiveStop:  // R9
        stop_state_ = MotionState::kProtectiveStop;
        stop_message_ = "protective stop " + where + "; acknowledge it on the teach pendant";
        break;
      case MoveFault::kEmergencyStop:  // R9
        stop_state_ = MotionState::kEmergencyStop;
        stop_message_ = "emergency stop " + where + "; release and acknowledge it on the teach pendant";
        break;
      case MoveFault::kDisconnect:  // R10
        link_lost_ = true;
        link_lost_reason_ = "connection lost " + where;
        break;
      case MoveFault::kHang:  // R6: the arm froze; nothing to latch, GetStatus keeps saying kMoving
      case MoveFault::kNone:
        break;
    }
  }
  return now;
}

Status SimulatedRobot::CheckLink(const char* call) const {
  if (link_lost_) {
    return RobotFailure(RobotError::kDisconnected, Name() + ": " + call + ": " + link_lost_reason_ +
                                                       "; Connect() again");
  }
  if (!connected_) return RobotFailure(RobotError::kNotConnected, Name() + ": " + call + ": not connected");
  return Status::Ok();
}

bool SimulatedRobot::Moving(double now) const { return move_.index >= 0 && now < move_.motion_end_s; }

Status SimulatedRobot::Connect() {
  ++counts_.connect;
  Advance();
  connected_ = true;
  link_lost_ = false;
  link_lost_reason_.clear();
  return Status::Ok();
}

void SimulatedRobot::Disconnect() {
  ++counts_.disconnect;
  Advance();
  connected_ = false;
}

Result<RobotIdentity> SimulatedRobot::Identity() {
  ++counts_.identity;
  Advance();
  if (Status link = CheckLink("Identity"); !link.ok()) return link;
  return identity_;
}

Result<JointLimits> SimulatedRobot::Limits() {
  ++counts_.limits;
  Advance();
  if (Status link = CheckLink("Limits"); !link.ok()) return link;
  return options_.limits;
}

Result<JointReading> SimulatedRobot::ReadJoints() {
  const int index = counts_.read++;
  const double now = Advance();
  if (Status link = CheckLink("ReadJoints"); !link.ok()) return link;
  JointReading reading;
  reading.time_s = now;
  reading.position_rad = JointsAt(now);
  reading.velocity_rad_s = JointVelocitiesAt(now);
  if (options_.encoder_noise_rad > 0) {
    std::normal_distribution<double> noise(0.0, options_.encoder_noise_rad);
    for (Eigen::Index j = 0; j < reading.position_rad.size(); ++j) reading.position_rad[j] += noise(rng_);
  }
  if (Has(options_.faults.never_settle_moves, counts_.start_move - 1)) {  // R7: the last move never rests
    reading.velocity_rad_s.setConstant(kNeverSettledVelocity_rad_s);
  }
  const JointReading genuine = reading;
  if (Has(options_.faults.stale_reads, index)) {  // R8: an old reading delivered again, older still
    if (have_last_reading_) reading = last_reading_;
    reading.time_s -= kStaleAge_s;
  } else {
    last_reading_ = genuine;
    have_last_reading_ = true;
  }
  if (Has(options_.faults.nan_reads, index)) {  // R8
    reading.position_rad[1] = std::numeric_limits<double>::quiet_NaN();
  }
  if (Has(options_.faults.short_reads, index)) {  // R8
    reading.position_rad.conservativeResize(reading.position_rad.size() - 1);
    reading.velocity_rad_s.conservativeResize(reading.velocity_rad_s.size() - 1);
  }
  return reading;
}

double SimulatedRobot::MoveDuration(const Eigen::VectorXd& from_rad, const Eigen::VectorXd& to_rad,
                                    double velocity_scaling) const {
  return std::max(options_.min_move_duration_s,
                  QuinticMoveDuration(from_rad, to_rad, options_.limits.max_velocity_rad_s, velocity_scaling));
}

Status SimulatedRobot::StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  const int index = counts_.start_move++;
  const double now = Advance();
  if (Status link = CheckLink("StartMove"); !link.ok()) return link;
  const std::string move_name = Name() + ": move #" + std::to_string(index) + " rejected: ";
  if (stop_state_ != MotionState::kIdle) {  // R9: never resume after a stop without a person
    return RobotFailure(RobotError::kRejected, move_name + stop_message_);
  }
  if (Moving(now)) {
    return RobotFailure(RobotError::kRejected,
                        move_name + "move #" + std::to_string(move_.index) + " is still running");
  }
  const std::string problem = CheckMoveTarget(options_.limits, target_rad, velocity_scaling);
  if (!problem.empty()) return RobotFailure(RobotError::kRejected, move_name + problem);
  const SimulatedRobotFaults& faults = options_.faults;
  if (Has(faults.reject_moves, index)) {  // R5
    return RobotFailure(RobotError::kRejected, move_name + "the controller refused the move (injected fault)");
  }

  // A jog still pending from the previous move happens before this one is commanded (R4).
  // (Nothing else lies in the future here: the previous move has ended.)
  for (Piece& piece : history_) piece.t_begin = std::min(piece.t_begin, now);

  Piece quintic;
  quintic.kind = Piece::Kind::kQuintic;
  quintic.t_begin = now + options_.latency_s;
  quintic.from_rad = JointsAt(quintic.t_begin);
  quintic.to_rad = target_rad;
  quintic.duration_s = MoveDuration(quintic.from_rad, target_rad, velocity_scaling);
  history_.push_back(quintic);
  const double arrival_s = quintic.t_begin + quintic.duration_s;

  move_ = CurrentMove();
  move_.index = index;
  move_.fault_time_s = quintic.t_begin + 0.5 * quintic.duration_s;
  if (Has(faults.hang_moves, index)) {
    move_.fault = MoveFault::kHang;  // R6
  } else if (Has(faults.protective_stop_moves, index)) {
    move_.fault = MoveFault::kProtectiveStop;  // R9
  } else if (Has(faults.emergency_stop_moves, index)) {
    move_.fault = MoveFault::kEmergencyStop;  // R9
  } else if (Has(faults.disconnect_moves, index)) {
    move_.fault = MoveFault::kDisconnect;  // R10
  }
  if (move_.fault != MoveFault::kNone) {
    // The arm halts half way (s(1/2) = 1/2: the midpoint), at rest.
    Piece halted;
    halted.t_begin = move_.fault_time_s;
    halted.to_rad = 0.5 * (quintic.from_rad + target_rad);
    history_.push_back(halted);
    move_.motion_end_s =
        move_.fault == MoveFault::kHang ? std::numeric_limits<double>::infinity() : move_.fault_time_s;
  } else {
    Piece arrived;
    arrived.t_begin = arrival_s;
    arrived.to_rad = target_rad;
    arrived.ring_start_s = arrival_s;
    arrived.ring_amplitude_rad = options_.settle_amplitude_rad;
    arrived.ring_tau_s = options_.settle_tau_s * (Has(faults.slow_settle_moves, index) ? kSlowSettleFactor : 1);  // R7
    history_.push_back(arrived);
    move_.motion_end_s = arrival_s;
    if (Has(faults.jog_after_moves, index)) {  // R4: someone jogs the arm once it has settled
      Piece jogged = arrived;
      jogged.t_begin = arrival_s + faults.jog_delay_s;
      jogged.to_rad = target_rad + faults.jog_offset_rad;
      history_.push_back(jogged);
    }
  }

  AcceptedMove accepted;
  accepted.index = index;
  accepted.target_rad = target_rad;
  accepted.velocity_scaling = velocity_scaling;
  accepted.command_time_s = now;
  accepted.start_time_s = quintic.t_begin;
  accepted.duration_s = quintic.duration_s;
  accepted_moves_.push_back(accepted);
  return Status::Ok();
}

Result<RobotStatus> SimulatedRobot::GetStatus() {
  ++counts_.status;
  const double now = Advance();
  if (Status link = CheckLink("GetStatus"); !link.ok()) return link;
  RobotStatus status;
  if (stop_state_ != MotionState::kIdle) {
    status.state = stop_state_;
    status.message = stop_message_;
  } else if (Moving(now)) {
    status.state = MotionState::kMoving;
    status.message = "move #" + std::to_string(move_.index);
  }
  return status;
}

Status SimulatedRobot::Stop() {
  ++counts_.stop;
  const double now = Advance();
  if (Status link = CheckLink("Stop"); !link.ok()) return link;
  if (!Moving(now)) return Status::Ok();
  // Halt where the arm is now (instantly: a simulation), dropping whatever was planned after now.
  const bool in_motion = PieceAt(now).kind == Piece::Kind::kQuintic;
  const Eigen::VectorXd here = JointsAt(now);
  TruncateAfter(now);
  if (in_motion) {
    Piece halted;
    halted.t_begin = now;
    halted.to_rad = here;
    history_.push_back(halted);
  }
  move_.motion_end_s = now;
  if (!move_.fault_fired) move_.fault = MoveFault::kNone;
  return Status::Ok();
}

void SimulatedRobot::AcknowledgeStop() {
  Advance();
  stop_state_ = MotionState::kIdle;
  stop_message_.clear();
}

void SimulatedRobot::TruncateAfter(double t) {
  while (history_.size() > 1 && history_.back().t_begin > t) history_.pop_back();
}

const SimulatedRobot::Piece& SimulatedRobot::PieceAt(double t) const {
  // The last piece that begins at or before t (later pieces win ties); before the first: the first.
  auto after = std::upper_bound(history_.begin(), history_.end(), t,
                                [](double time, const Piece& piece) { return time < piece.t_begin; });
  return after == history_.begin() ? history_.front() : *(after - 1);
}

Eigen::VectorXd SimulatedRobot::JointsAt(double t) const {
  const Piece& piece = PieceAt(t);
  if (piece.kind == Piece::Kind::kQuintic) {
    const double tau = std::clamp((t - piece.t_begin) / piece.duration_s, 0.0, 1.0);
    return piece.from_rad + QuinticS(tau) * (piece.to_rad - piece.from_rad);
  }
  const double since_s = t - piece.ring_start_s;
  if (piece.ring_amplitude_rad == 0 || since_s <= 0 || since_s >= RingCutoff(piece)) return piece.to_rad;
  const double ring = piece.ring_amplitude_rad * std::exp(-since_s / piece.ring_tau_s) *
                      std::sin(2 * kPi * options_.settle_frequency_hz * since_s);
  return piece.to_rad.array() + ring;
}

Eigen::VectorXd SimulatedRobot::JointVelocitiesAt(double t) const {
  const Piece& piece = PieceAt(t);
  const Eigen::Index n = options_.num_joints();
  if (piece.kind == Piece::Kind::kQuintic) {
    const double tau = (t - piece.t_begin) / piece.duration_s;
    if (tau < 0 || tau > 1) return Eigen::VectorXd::Zero(n);
    return (QuinticRate(tau) / piece.duration_s) * (piece.to_rad - piece.from_rad);
  }
  const double since_s = t - piece.ring_start_s;
  if (piece.ring_amplitude_rad == 0 || since_s <= 0 || since_s >= RingCutoff(piece)) return Eigen::VectorXd::Zero(n);
  const double omega = 2 * kPi * options_.settle_frequency_hz;
  const double rate = piece.ring_amplitude_rad * std::exp(-since_s / piece.ring_tau_s) *
                      (omega * std::cos(omega * since_s) - std::sin(omega * since_s) / piece.ring_tau_s);
  return Eigen::VectorXd::Constant(n, rate);
}

}  // namespace selfcal::robot
