#include "robot/manual_robot.h"

#include <cctype>
#include <cmath>
#include <iomanip>
#include <istream>
#include <ostream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "robot/line_protocol.h"

namespace selfcal::robot {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
constexpr const char* kName = "manual robot";

std::string Trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

Status OperatorAbort(const std::string& what) {
  return RobotFailure(RobotError::kOperatorAbort, std::string(kName) + ": " + what);
}

}  // namespace

ManualRobot::ManualRobot(std::istream& in, std::ostream& out, JointLimits limits, Clock& clock, Robot* joint_reader)
    : in_(in), out_(out), limits_(std::move(limits)), clock_(clock), joint_reader_(joint_reader) {
  const std::string problem = CheckJointLimits(limits_);
  SELFCAL_CHECK(problem.empty(), "manual robot: " << problem);
}

Status ManualRobot::CheckConnected(const char* call) const {
  if (connected_) return Status::Ok();
  return RobotFailure(RobotError::kNotConnected, std::string(kName) + ": " + call + ": not connected");
}

bool ManualRobot::ReadAnswer(std::string* answer) {
  out_.flush();
  if (!std::getline(in_, *answer)) return false;
  *answer = Trimmed(*answer);
  for (char& c : *answer) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return true;
}

Status ManualRobot::Connect() {
  if (joint_reader_ != nullptr) {
    if (Status reader = joint_reader_->Connect(); !reader.ok()) return reader;
  }
  connected_ = true;
  out_ << kName << ": you move the robot. For every pose you will be shown the target joint angles in degrees;\n"
       << "jog the robot there with the teach pendant and type `done` (or `abort` to end the session).\n";
  out_.flush();
  return Status::Ok();
}

void ManualRobot::Disconnect() {
  if (joint_reader_ != nullptr) joint_reader_->Disconnect();
  connected_ = false;
  awaiting_operator_ = false;
}

Result<RobotIdentity> ManualRobot::Identity() {
  if (Status connected = CheckConnected("Identity"); !connected.ok()) return connected;
  RobotIdentity identity;
  identity.model = "manual";
  if (joint_reader_ != nullptr) {
    const Result<RobotIdentity> reader = joint_reader_->Identity();
    if (!reader.ok()) return reader.status();
    identity = *reader;
  }
  identity.backend = "manual";
  identity.real_hardware = true;
  return identity;
}

Result<JointLimits> ManualRobot::Limits() {
  if (Status connected = CheckConnected("Limits"); !connected.ok()) return connected;
  return limits_;
}

std::string ManualRobot::ParseTypedJoints(const std::string& answer, Eigen::VectorXd* joints_rad) const {
  std::string spaced = answer;
  for (char& c : spaced) {
    if (c == ',' || c == '\t' || c == ';') c = ' ';
  }
  const std::vector<std::string_view> tokens = protocol::SplitTokens(spaced);
  const Eigen::Index n = limits_.lower_rad.size();
  if (static_cast<Eigen::Index>(tokens.size()) != n) {
    return "expected " + std::to_string(n) + " values, got " + std::to_string(tokens.size());
  }
  joints_rad->resize(n);
  std::ostringstream problem;
  for (Eigen::Index j = 0; j < n; ++j) {
    double degrees = 0;
    if (!protocol::ParseNumber(tokens[static_cast<size_t>(j)], &degrees) || !std::isfinite(degrees)) {
      problem << "joint " << j + 1 << ": \"" << tokens[static_cast<size_t>(j)] << "\" is not a finite number";
      return problem.str();
    }
    (*joints_rad)[j] = degrees / kDegPerRad;
    if ((*joints_rad)[j] < limits_.lower_rad[j] || (*joints_rad)[j] > limits_.upper_rad[j]) {
      problem << "joint " << j + 1 << ": " << degrees << " deg is outside its limits [" << limits_.lower_rad[j] * kDegPerRad
              << ", " << limits_.upper_rad[j] * kDegPerRad << "] deg";
      return problem.str();
    }
  }
  return "";
}

Result<JointReading> ManualRobot::ReadJoints() {
  if (Status connected = CheckConnected("ReadJoints"); !connected.ok()) return connected;
  if (joint_reader_ != nullptr) {
    Result<JointReading> reading = joint_reader_->ReadJoints();
    if (reading.ok()) last_joints_rad_ = reading->position_rad;
    return reading;
  }
  const Eigen::Index n = limits_.lower_rad.size();
  for (int attempt = 0; attempt <= kMaxReAsks; ++attempt) {
    out_ << kName << ": type the " << n << " joint angles in degrees as the pendant shows them (joint 1 first), "
         << "or `abort`:\n";
    std::string answer;
    if (!ReadAnswer(&answer)) return OperatorAbort("end of input while waiting for the joint angles");
    if (answer == "abort") return OperatorAbort("the operator aborted while asked for the joint angles");
    JointReading reading;
    const std::string problem = ParseTypedJoints(answer, &reading.position_rad);
    if (problem.empty()) {
      reading.velocity_rad_s = Eigen::VectorXd::Zero(n);
      reading.time_s = clock_.Now();
      last_joints_rad_ = reading.position_rad;
      return reading;
    }
    out_ << kName << ": not accepted: " << problem << "\n";
  }
  return RobotFailure(RobotError::kBadReading, std::string(kName) + ": no valid joint angles after " +
                                                   std::to_string(kMaxReAsks + 1) + " attempts");
}

Status ManualRobot::StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  if (Status connected = CheckConnected("StartMove"); !connected.ok()) return connected;
  const int index = moves_++;
  const std::string name = std::string(kName) + ": move #" + std::to_string(index);
  if (awaiting_operator_) {
    return RobotFailure(RobotError::kRejected, name + " rejected: the operator has not finished the last move");
  }
  if (const std::string problem = CheckMoveTarget(limits_, target_rad, velocity_scaling); !problem.empty()) {
    return RobotFailure(RobotError::kRejected, name + " rejected: " + problem);
  }
  const bool have_reading = last_joints_rad_.size() == target_rad.size();
  out_ << name << ": jog the robot to these joint angles, then type `done` (or `abort`):\n" << std::fixed
       << std::setprecision(3);
  for (Eigen::Index j = 0; j < target_rad.size(); ++j) {
    out_ << "  joint " << j + 1 << ": " << std::setw(9) << target_rad[j] * kDegPerRad << " deg";
    if (have_reading) {
      out_ << "  (" << std::showpos << (target_rad[j] - last_joints_rad_[j]) * kDegPerRad << std::noshowpos
           << " deg from the last reading)";
    }
    out_ << "\n";
  }
  if (!have_reading) out_ << "  (no joint reading yet: the difference from the current pose is unknown)\n";
  out_ << std::defaultfloat << std::setprecision(6);
  out_.flush();
  awaiting_operator_ = true;
  return Status::Ok();
}

Result<RobotStatus> ManualRobot::GetStatus() {
  if (Status connected = CheckConnected("GetStatus"); !connected.ok()) return connected;
  RobotStatus status;
  if (!awaiting_operator_) return status;
  std::string answer;
  if (!ReadAnswer(&answer)) {
    awaiting_operator_ = false;
    return OperatorAbort("end of input while waiting for `done`");
  }
  if (answer == "done") {
    awaiting_operator_ = false;
    return status;
  }
  if (answer == "abort") {
    awaiting_operator_ = false;
    return OperatorAbort("the operator aborted move #" + std::to_string(moves_ - 1));
  }
  out_ << kName << ": type `done` once the robot is at the target, or `abort`\n";
  status.state = MotionState::kMoving;
  status.message = "waiting for the operator";
  return status;
}

Status ManualRobot::Stop() {
  out_ << kName << ": STOP: stop moving the robot now.";
  if (awaiting_operator_) out_ << " Move #" << moves_ - 1 << " is cancelled.";
  out_ << "\n";
  out_.flush();
  awaiting_operator_ = false;
  if (joint_reader_ != nullptr) return joint_reader_->Stop();
  return Status::Ok();
}

}  // namespace selfcal::robot
