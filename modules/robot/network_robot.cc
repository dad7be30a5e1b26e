#include "robot/network_robot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

#include "base/terminal_text.h"

namespace selfcal::robot {
namespace {

using protocol::RequestKind;

constexpr double kByeTimeout_s = 0.2;  // Disconnect() does not wait longer for the BYE reply

// "serial sim-1, now sim-2" for the fields that differ ("" when none does); empty `expected` fields
// are not compared when `skip_empty`.
std::string IdentityDifference(const RobotIdentity& expected, const RobotIdentity& seen, bool skip_empty) {
  std::string difference;
  const auto compare = [&](const char* field, const std::string& a, const std::string& b) {
    if ((skip_empty && a.empty()) || a == b) return;
    difference += std::string(difference.empty() ? "" : "; ") + field + " \"" + a + "\", now \"" + b + "\"";
  };
  compare("model", expected.model, seen.model);
  compare("serial", expected.serial, seen.serial);
  compare("calibration id", expected.calibration_id, seen.calibration_id);
  return difference;
}

// "\x1b" for ESC (base/terminal_text.h): control characters and invalid UTF-8 escaped, so that a
// controller cannot drive the terminal; printable UTF-8 (a model name with accents) kept.
std::string Sanitised(const std::string& text) { return TerminalSafe(text); }

Status SanitisedStatus(const Status& status) {
  if (status.ok()) return status;
  return RobotFailure(RobotErrorOf(status), Sanitised(status.message()));
}

}  // namespace

Status NetworkRobotOptions::Validate() const {
  std::ostringstream problems;
  if (!(std::isfinite(connect_timeout_s) && connect_timeout_s > 0)) {
    problems << " connect_timeout_s = " << connect_timeout_s << " must be finite and > 0;";
  }
  if (!(std::isfinite(reply_timeout_s) && reply_timeout_s > 0)) {
    problems << " reply_timeout_s = " << reply_timeout_s << " must be finite and > 0;";
  }
  if (max_line_bytes < 256) problems << " max_line_bytes = " << max_line_bytes << " must be at least 256;";
  if (config_limits) {
    const JointLimits& c = *config_limits;
    if (c.lower_rad.size() == 0 || c.lower_rad.size() != c.upper_rad.size() || !c.lower_rad.allFinite() ||
        !c.upper_rad.allFinite() || (c.upper_rad - c.lower_rad).minCoeff() < 0) {
      problems << " config_limits must give finite lower <= upper bounds for at least one joint;";
    }
  }
  if (!(rest_interval_s >= 0 && rest_interval_s <= 1 && rest_tolerance_rad > 0 && rest_velocity_rad_s > 0)) {
    problems << " rest_interval_s must lie in [0, 1] s, rest_tolerance_rad and rest_velocity_rad_s be > 0;";
  }
  if (problems.str().empty()) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput, "network robot options:" + problems.str());
}

NetworkRobot::NetworkRobot(std::string host, int port, NetworkRobotOptions options)
    : host_(std::move(host)),
      port_(port),
      options_(std::move(options)),
      name_("network robot " + host_ + ":" + std::to_string(port_)),
      last_controller_time_s_(std::numeric_limits<double>::quiet_NaN()) {
  const Status valid = options_.Validate();
  SELFCAL_CHECK(valid.ok(), valid.message());
}

NetworkRobot::~NetworkRobot() = default;

Status NetworkRobot::LinkStatus(const char* call) const {
  switch (link_) {
    case Link::kUp:
      return Status::Ok();
    case Link::kBroken:
      return RobotFailure(RobotError::kDisconnected,
                          name_ + ": " + call + ": the connection was lost (" + broken_reason_ + "); Connect() again");
    case Link::kNeverConnected:
    case Link::kClosed:
      break;
  }
  return RobotFailure(RobotError::kNotConnected, name_ + ": " + call + ": not connected");
}

void NetworkRobot::Break(const std::string& reason) {
  socket_.Close();
  if (link_ == Link::kUp) {
    link_ = Link::kBroken;
    broken_reason_ = reason;
  }
}

Result<std::string> NetworkRobot::RoundTrip(RequestKind kind, const std::string& request) {
  const std::string word = protocol::RequestWord(kind);
  if (socket_.has_buffered_input()) {
    Break("unrequested data from the controller");
    return RobotFailure(RobotError::kProtocol, name_ + ": " + word + ": the controller sent a line nobody asked for");
  }
  LineIoResult io = socket_.WriteLine(request, options_.reply_timeout_s);
  std::string reply;
  if (io.ok()) io = socket_.ReadLine(&reply, options_.reply_timeout_s);
  switch (io.outcome) {
    case LineIo::kOk:
      return reply;
    case LineIo::kTimeout: {
      std::ostringstream message;
      message << "no reply to " << word << " within " << options_.reply_timeout_s << " s";
      Break(message.str());
      return RobotFailure(RobotError::kTimeout, name_ + ": " + message.str() + "; connection closed");
    }
    case LineIo::kTooLong:
      Break("reply too long");
      return RobotFailure(RobotError::kProtocol, name_ + ": " + word + ": reply too long (" + io.error +
                                                     "); connection closed");
    case LineIo::kClosed:
    case LineIo::kFailed:
      break;
  }
  const std::string reason = "closed during " + word + ": " + io.error;
  Break(reason);
  return RobotFailure(RobotError::kDisconnected, name_ + ": connection " + reason);
}

Status NetworkRobot::Handshake() { return SanitisedStatus(HandshakeUnsanitised()); }

Status NetworkRobot::HandshakeUnsanitised() {
  const Result<std::string> hello_line = RoundTrip(RequestKind::kHello, protocol::HelloRequest());
  if (!hello_line.ok()) return hello_line.status();
  Result<protocol::HelloInfo> hello = protocol::ParseHelloReply(*hello_line, name_);
  if (!hello.ok()) return hello.status();
  RobotIdentity& said = hello.value().identity;
  for (std::string* field : {&said.model, &said.serial, &said.calibration_id}) {
    *field = Sanitised(*field);
  }
  if (first_hello_) {  // R10, R13: after a reconnect it must be the same arm
    std::string difference = IdentityDifference(first_hello_->identity, hello->identity, false);
    if (first_hello_->num_joints != hello->num_joints) {
      difference += (difference.empty() ? "" : "; ") + std::string("joints ") +
                    std::to_string(first_hello_->num_joints) + ", now " + std::to_string(hello->num_joints);
    }
    if (first_hello_->identity.real_hardware != hello->identity.real_hardware) {
      difference += std::string(difference.empty() ? "" : "; ") + "real hardware flag changed";
    }
    if (!difference.empty()) {
      return RobotFailure(RobotError::kProtocol, name_ + ": the controller is not the one first connected (" +
                                                     difference + "); refusing it");
    }
  }
  if (options_.expected_identity) {  // R12, R13
    const std::string difference = IdentityDifference(*options_.expected_identity, hello->identity, true);
    if (!difference.empty()) {
      return RobotFailure(RobotError::kProtocol, name_ + ": the controller is not the expected robot (expected " +
                                                     difference + "); refusing it");
    }
  }
  const Result<std::string> limits_line = RoundTrip(RequestKind::kLimits, "LIMITS");
  if (!limits_line.ok()) return limits_line.status();
  Result<JointLimits> limits = protocol::ParseLimitsReply(*limits_line, hello->num_joints, name_);
  if (!limits.ok()) return limits.status();
  if (const std::string problem = CheckJointLimits(*limits); !problem.empty()) {
    return RobotFailure(RobotError::kProtocol, name_ + ": LIMITS: " + problem);
  }
  if (Status s = CheckAgainstConfig(*hello, &limits.value()); !s.ok()) return s;
  hello_ = std::move(hello).value();
  hello_.identity.backend = "network";
  limits_ = std::move(limits).value();
  if (!first_hello_) first_hello_ = hello_;
  return Status::Ok();
}

Status NetworkRobot::CheckAgainstConfig(const protocol::HelloInfo& hello, JointLimits* limits) {
  if (!options_.config_limits) return Status::Ok();
  const JointLimits& config = *options_.config_limits;
  const Eigen::Index n = config.lower_rad.size();
  if (hello.num_joints != n) {
    return RobotFailure(RobotError::kProtocol, name_ + ": HELLO reports " + std::to_string(hello.num_joints) +
                                                   " joints, the robot config has " + std::to_string(n));
  }
  if (limits->lower_rad.size() != n || limits->upper_rad.size() != n || limits->max_velocity_rad_s.size() != n) {
    return RobotFailure(RobotError::kProtocol, name_ + ": LIMITS has " + std::to_string(limits->lower_rad.size()) +
                                                   " joints, the robot config has " + std::to_string(n));
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const double lower = std::max(limits->lower_rad[j], config.lower_rad[j]);
    const double upper = std::min(limits->upper_rad[j], config.upper_rad[j]);
    std::ostringstream what;
    what.precision(6);
    what << "joint " << j + 1 << ": the controller's limits [" << limits->lower_rad[j] << ", " << limits->upper_rad[j]
         << "] rad and the robot config's [" << config.lower_rad[j] << ", " << config.upper_rad[j] << "] rad";
    if (lower > upper) {
      return RobotFailure(RobotError::kProtocol, name_ + ": LIMITS: " + what.str() + " do not overlap");
    }
    if ((lower != limits->lower_rad[j] || upper != limits->upper_rad[j]) && options_.log) {
      std::ostringstream narrower;
      narrower.precision(6);
      narrower << ": the narrower [" << lower << " " << upper << "] rad is used";
      options_.log(name_ + ": " + what.str() + narrower.str());
    }
    limits->lower_rad[j] = lower;
    limits->upper_rad[j] = upper;
  }
  return Status::Ok();
}

Status NetworkRobot::CheckStartReading() {
  if (!options_.config_limits) return Status::Ok();
  return CheckStartAtRest([this] { return ReadJoints(); }, [this](double s) { clock_.SleepFor(s); }, limits_,
                          {options_.rest_interval_s, options_.rest_tolerance_rad, options_.rest_velocity_rad_s}, name_);
}

Status NetworkRobot::Connect() {
  if (link_ == Link::kUp && socket_.is_open()) return Status::Ok();
  Result<LineSocket> socket =
      LineSocket::Connect(host_, port_, options_.connect_timeout_s, options_.max_line_bytes);
  if (!socket.ok()) return RobotFailure(RobotErrorOf(socket.status()), name_ + ": " + socket.status().message());
  socket_ = std::move(socket).value();
  const Status handshake = Handshake();
  if (!handshake.ok()) {
    socket_.Close();
    return handshake;
  }
  link_ = Link::kUp;
  broken_reason_.clear();
  if (Status start = SanitisedStatus(CheckStartReading()); !start.ok()) {
    socket_.Close();  // nothing was sent to the arm: no MOVE, no STOP
    link_ = Link::kClosed;
    return start;
  }
  return Status::Ok();
}

void NetworkRobot::Disconnect() {
  if (link_ == Link::kUp && socket_.is_open()) {
    std::string ignored;
    if (socket_.WriteLine("BYE", kByeTimeout_s).ok()) socket_.ReadLine(&ignored, kByeTimeout_s);
  }
  socket_.Close();
  link_ = Link::kClosed;
}

Result<RobotIdentity> NetworkRobot::Identity() {
  if (Status link = LinkStatus("Identity"); !link.ok()) return link;
  return hello_.identity;
}

Result<JointLimits> NetworkRobot::Limits() {
  if (Status link = LinkStatus("Limits"); !link.ok()) return link;
  const Result<std::string> line = RoundTrip(RequestKind::kLimits, "LIMITS");
  if (!line.ok()) return line.status();
  Result<JointLimits> limits = protocol::ParseLimitsReply(*line, hello_.num_joints, name_);
  if (!limits.ok()) return SanitisedStatus(limits.status());
  if (Status s = CheckAgainstConfig(hello_, &limits.value()); !s.ok()) return SanitisedStatus(s);
  limits_ = *limits;
  return limits;
}

Result<JointReading> NetworkRobot::ReadJoints() {
  if (Status link = LinkStatus("ReadJoints"); !link.ok()) return link;
  const Result<std::string> line = RoundTrip(RequestKind::kJoints, "JOINTS");
  const double arrived_s = clock_.Now();  // the session's clock, not the controller's (see header)
  if (!line.ok()) return line.status();
  Result<JointReading> reading = protocol::ParseJointsReply(*line, name_);
  if (!reading.ok()) return SanitisedStatus(reading.status());
  last_controller_time_s_ = reading->time_s;
  reading.value().time_s = arrived_s;
  return reading;
}

Status NetworkRobot::StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  if (Status link = LinkStatus("StartMove"); !link.ok()) return link;
  if (const std::string problem = CheckMoveTarget(limits_, target_rad, velocity_scaling); !problem.empty()) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + problem);
  }
  const Result<std::string> line = RoundTrip(RequestKind::kMove, protocol::MoveRequest(target_rad, velocity_scaling));
  if (!line.ok()) return line.status();
  return SanitisedStatus(protocol::ParseOkReply(*line, RequestKind::kMove, RobotError::kRejected, name_));
}

Result<RobotStatus> NetworkRobot::GetStatus() {
  if (Status link = LinkStatus("GetStatus"); !link.ok()) return link;
  const Result<std::string> line = RoundTrip(RequestKind::kStatus, "STATUS");
  if (!line.ok()) return line.status();
  Result<RobotStatus> status = protocol::ParseStatusReply(*line, name_);
  if (!status.ok()) return SanitisedStatus(status.status());
  status.value().message = Sanitised(status->message);
  return status;
}

Status NetworkRobot::Stop() {
  if (Status link = LinkStatus("Stop"); !link.ok()) return link;
  const Result<std::string> line = RoundTrip(RequestKind::kStop, "STOP");
  if (!line.ok()) return line.status();
  return SanitisedStatus(protocol::ParseOkReply(*line, RequestKind::kStop, RobotError::kRejected, name_));
}

}  // namespace selfcal::robot
