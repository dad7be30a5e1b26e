#include "robot/ur_robot.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <utility>

#include "base/terminal_text.h"

namespace selfcal::robot {
namespace {

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::string Joined(const std::vector<std::string>& parts) {
  std::string text;
  for (size_t i = 0; i < parts.size(); ++i) text += (i ? "," : "") + parts[i];
  return text;
}

}  // namespace

Status UrRobotOptions::Validate() const {
  std::ostringstream problems;
  for (int port : {rtde_port, secondary_port, dashboard_port}) {
    if (port < 1 || port > 65535) problems << " port " << port << " must lie in 1-65535;";
  }
  if (!(connect_timeout_s > 0 && reply_timeout_s > 0 && std::isfinite(connect_timeout_s) && std::isfinite(reply_timeout_s))) {
    problems << " timeouts must be finite and > 0;";
  }
  if (!(rtde_frequency_hz >= 1 && rtde_frequency_hz <= 500)) problems << " rtde_frequency_hz must lie in [1, 500];";
  if (limits.lower_rad.size() != 6) problems << " limits must give the six joints of a UR arm;";
  if (const std::string bad = limits.lower_rad.size() == 6 ? CheckJointLimits(limits) : ""; !bad.empty()) {
    problems << " " << bad << ";";
  }
  if (!(rest.interval_s >= 0 && rest.interval_s <= 1 && rest.tolerance_rad > 0 && rest.velocity_rad_s > 0 &&
        target_tolerance_rad > 0 && acceleration_per_velocity > 0 && stop_deceleration_rad_s2 > 0)) {
    problems << " rest, tolerance, acceleration and deceleration settings must be > 0;";
  }
  if (problems.str().empty()) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput, "UR robot options:" + problems.str());
}

Result<UrRobotOptions> UrRunOptions(const std::string& host, const std::vector<int>& ports, JointLimits position_limits) {
  const size_t colon = host.find(':');
  const bool host_port = colon != std::string::npos && host.find(':', colon + 1) == std::string::npos;
  if (host.empty() || host_port) {
    return Status::Error(ErrorCode::kInvalidInput, "--address \"" + host + "\": --backend ur takes the controller's HOST "
                                                   "alone (its ports are UR's; --ur-ports for the loopback fake)");
  }
  if (!ports.empty() && ports.size() != 3) {
    return Status::Error(ErrorCode::kInvalidInput, "--ur-ports takes three ports: RTDE, secondary, Dashboard");
  }
  UrRobotOptions options;
  if (ports.size() == 3) {
    options.rtde_port = ports[0];
    options.secondary_port = ports[1];
    options.dashboard_port = ports[2];
  }
  position_limits.max_velocity_rad_s = Eigen::VectorXd::Constant(position_limits.lower_rad.size(), kUrJointSpeedLimit_rad_s);
  options.limits = std::move(position_limits);
  if (Status valid = options.Validate(); !valid.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, valid.message() + " (the robot config must describe a six-joint UR arm)");
  }
  return options;
}

UrRobot::UrRobot(std::string host, UrRobotOptions options)
    : host_(std::move(host)), options_(std::move(options)), name_("UR robot " + host_) {
  const Status valid = options_.Validate();
  SELFCAL_CHECK(valid.ok(), valid.message());
}

UrRobot::~UrRobot() { CloseAll(); }

void UrRobot::StartReader() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_.reset();
    reader_failure_ = Status::Ok();
  }
  stop_reader_ = false;
  reader_ = std::thread([this] { ReadStreams(); });
}

void UrRobot::ReadStreams() {
  while (!stop_reader_.load()) {
    Status failure;
    Result<ur::RtdePackage> package = ReadRtdePackage(0.02);
    if (package.ok() && package->type == ur::kRtdeDataPackage) {
      Result<ur::UrState> state = ur::DecodeStateData(package->payload, recipe_id_);
      if (state.ok()) {
        std::lock_guard<std::mutex> lock(mutex_);
        latest_ = *state;
        latest_s_ = clock_.Now();
        ++packages_read_;
      } else {
        failure = RobotFailure(RobotError::kProtocol, "RTDE: " + state.status().message());
      }
    } else if (!package.ok() && RobotErrorOf(package.status()) != RobotError::kTimeout) {
      failure = package.status();
    }
    if (LineIoResult io; failure.ok() && !(io = secondary_.DiscardInput()).ok()) {
      failure = RobotFailure(RobotError::kDisconnected, "secondary interface lost: " + io.error);
    }
    if (!failure.ok()) {
      std::lock_guard<std::mutex> lock(mutex_);
      reader_failure_ = failure;
      return;
    }
  }
}

void UrRobot::CloseAll() {
  stop_reader_ = true;
  if (reader_.joinable()) reader_.join();
  rtde_.Close();
  secondary_.Close();
  dashboard_.Close();
  target_.reset();
}

Status UrRobot::LinkStatus(const char* call) const {
  if (link_ == Link::kUp) return Status::Ok();
  if (link_ == Link::kBroken) {
    return RobotFailure(RobotError::kDisconnected,
                        name_ + ": " + call + ": the connection was lost (" + broken_reason_ + "); Connect() again");
  }
  return RobotFailure(RobotError::kNotConnected, name_ + ": " + call + ": not connected");
}

Status UrRobot::Broken(RobotError error, const std::string& reason) {
  CloseAll();
  if (link_ == Link::kUp) {
    link_ = Link::kBroken;
    broken_reason_ = reason;
  }
  return RobotFailure(error, name_ + ": " + reason);
}

Result<std::string> UrRobot::Dashboard(const std::string& command) {
  LineIoResult io = dashboard_.WriteLine(command, options_.reply_timeout_s);
  std::string reply;
  if (io.ok()) io = dashboard_.ReadLine(&reply, options_.reply_timeout_s);
  if (!io.ok()) {
    return Broken(RobotErrorOfIo(io.outcome), "Dashboard server (port " + std::to_string(options_.dashboard_port) +
                                             "): no answer to \"" + command + "\": " + io.error);
  }
  return TerminalSafe(reply);
}

Status UrRobot::CheckDashboard() {
  Result<std::string> remote = Dashboard("is in remote control");
  if (!remote.ok()) return remote.status();
  if (Lower(*remote) == "false") {
    return RobotFailure(RobotError::kRejected, name_ + ": remote control is off (Dashboard: \"is in remote control\" "
                                                       "answers false): switch the teach pendant to Remote Control");
  }
  if (Lower(*remote) != "true" && options_.log) {
    options_.log(name_ + ": the Dashboard cannot tell remote control (\"" + *remote + "\"); a controller before "
                                                                                     "PolyScope 5 has no such mode");
  }
  Result<std::string> safety = Dashboard("safetystatus");
  if (!safety.ok()) return safety.status();
  const std::string status = ur::DashboardValue(*safety, "Safetystatus:");
  if (status == "PROTECTIVE_STOP" || status == "SAFEGUARD_STOP") {
    return RobotFailure(RobotError::kProtectiveStop,
                        name_ + ": the arm is in " + status + ": a person must clear it at the teach pendant");
  }
  if (status.find("EMERGENCY") != std::string::npos) {
    return RobotFailure(RobotError::kEmergencyStop, name_ + ": " + status + ": a person must release it");
  }
  if (status != "NORMAL" && status != "REDUCED") {
    return RobotFailure(RobotError::kRejected, name_ + ": safety status \"" + *safety + "\", not NORMAL");
  }
  Result<std::string> mode = Dashboard("robotmode");
  if (!mode.ok()) return mode.status();
  if (ur::DashboardValue(*mode, "Robotmode:") != "RUNNING") {
    return RobotFailure(RobotError::kRejected, name_ + ": \"" + *mode + "\": power the arm on and release its brakes "
                                                                         "at the teach pendant");
  }
  Result<std::string> model = Dashboard("get_robot_model");
  if (!model.ok()) return model.status();
  Result<std::string> serial = Dashboard("get_serial_number");
  if (!serial.ok()) return serial.status();
  identity_.model = *model;
  identity_.serial = *serial;
  return Status::Ok();
}

Status UrRobot::ReadKinematics() {
  const double deadline_s = clock_.Now() + options_.connect_timeout_s;
  while (true) {
    const double left_s = std::max(0.0, deadline_s - clock_.Now());
    std::string header, body;
    LineIoResult io = secondary_.ReadBytes(&header, 5, left_s);
    Result<uint32_t> size = io.ok() ? ur::PrimaryMessageSize(header) : Result<uint32_t>(Status::Ok());
    if (io.ok() && !size.ok()) return Broken(RobotError::kProtocol, "secondary interface: " + size.status().message());
    if (io.ok()) io = secondary_.ReadBytes(&body, *size - 5, left_s);
    if (!io.ok()) {
      return Broken(RobotErrorOfIo(io.outcome), "secondary interface (port " + std::to_string(options_.secondary_port) +
                                               "): no robot state with the kinematics info: " + io.error);
    }
    Result<std::optional<ur::KinematicsInfo>> info = ur::KinematicsInfoOf(header + body);
    if (!info.ok()) return Broken(RobotError::kProtocol, "secondary interface: " + info.status().message());
    if (*info) {
      kinematics_ = **info;
      return Status::Ok();
    }
  }
}

Result<ur::RtdePackage> UrRobot::ReadRtdePackage(double timeout_s) {
  std::string header, payload;
  LineIoResult io = rtde_.ReadBytes(&header, 3, timeout_s);
  if (io.outcome == LineIo::kTimeout) return RobotFailure(RobotError::kTimeout, "no RTDE package");
  Result<uint16_t> size = io.ok() ? ur::RtdePackageSize(header) : Result<uint16_t>(uint16_t{3});
  if (!size.ok()) return RobotFailure(RobotError::kProtocol, "RTDE: " + size.status().message());
  if (io.ok()) io = rtde_.ReadBytes(&payload, *size - 3, options_.reply_timeout_s);
  if (!io.ok()) {
    return RobotFailure(RobotErrorOfIo(io.outcome), "RTDE (port " + std::to_string(options_.rtde_port) + "): " + io.error);
  }
  return ur::RtdePackage{static_cast<uint8_t>(header[2]), payload};
}

Status UrRobot::StartRtde() {
  // Each request and its answer, text messages ('M') skipped.
  const auto ask = [this](const std::string& request, uint8_t type) -> Result<std::string> {
    if (LineIoResult io = rtde_.WriteBytes(request, options_.reply_timeout_s); !io.ok()) {
      return Broken(RobotErrorOfIo(io.outcome), "RTDE: " + io.error);
    }
    while (true) {
      Result<ur::RtdePackage> reply = ReadRtdePackage(options_.reply_timeout_s);
      if (!reply.ok() && RobotErrorOf(reply.status()) == RobotError::kTimeout) {
        return Broken(RobotError::kTimeout, "RTDE: no answer to request '" + std::string(1, char(type)) + "'");
      }
      if (!reply.ok()) return Broken(RobotErrorOf(reply.status()), reply.status().message());
      if (reply->type == type) return reply->payload;
      if (reply->type != ur::kRtdeTextMessage) {
        return Broken(RobotError::kProtocol, "RTDE: package type " + std::to_string(reply->type) +
                                                 " in answer to '" + std::string(1, char(type)) + "'");
      }
    }
  };
  Result<std::string> version = ask(ur::ProtocolVersionRequest(ur::kRtdeProtocolVersion), ur::kRtdeRequestProtocolVersion);
  Result<bool> accepted = version.ok() ? ur::ParseAccepted(*version, "protocol version") : version.status();
  if (!accepted.ok() || !*accepted) {
    return accepted.ok() ? Broken(RobotError::kProtocol, "RTDE: protocol version 2 refused (a controller before 3.5?)")
                         : accepted.status();
  }
  Result<std::string> setup = ask(ur::SetupOutputsRequest(options_.rtde_frequency_hz, ur::StateRecipeNames()),
                                  ur::kRtdeSetupOutputs);
  if (!setup.ok()) return setup.status();
  Result<ur::SetupOutputsReply> recipe = ur::ParseSetupOutputsReply(*setup);
  if (!recipe.ok()) return Broken(RobotError::kProtocol, "RTDE: " + recipe.status().message());
  if (recipe->types != ur::StateRecipeTypes()) {
    return Broken(RobotError::kProtocol, "RTDE: the output recipe " + Joined(ur::StateRecipeNames()) +
                                             " was answered with the types \"" + TerminalSafe(Joined(recipe->types)) +
                                             "\", not " + Joined(ur::StateRecipeTypes()) +
                                             " (NOT_FOUND: the controller's software lacks that variable)");
  }
  recipe_id_ = recipe->recipe_id;
  Result<std::string> start = ask(EncodeRtde(ur::kRtdeStart, ""), ur::kRtdeStart);
  Result<bool> started = start.ok() ? ur::ParseAccepted(*start, "start") : start.status();
  if (!started.ok()) return started.status();
  if (!*started) return Broken(RobotError::kProtocol, "RTDE: the controller refused to start the data stream");
  return Status::Ok();
}

Result<ur::UrState> UrRobot::LatestState(double* arrival_s, double not_before_s) {
  const double deadline_s = clock_.Now() + options_.reply_timeout_s;
  while (true) {
    Status failure;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      failure = reader_failure_;
      if (failure.ok() && latest_ && clock_.Now() - latest_s_ <= options_.reply_timeout_s &&
          latest_s_ >= not_before_s) {
        last_state_ = *latest_;
        if (arrival_s != nullptr) *arrival_s = latest_s_;
        return last_state_;
      }
    }
    if (!failure.ok()) return Broken(RobotErrorOf(failure), failure.message());
    if (clock_.Now() > deadline_s) {
      std::ostringstream message;
      message << "RTDE: no data package within " << options_.reply_timeout_s << " s";
      return Broken(RobotError::kTimeout, message.str());
    }
    clock_.SleepFor(0.002);
  }
}

Status UrRobot::ConnectUnchecked() {
  const auto open = [this](LineSocket* socket, int port) -> Status {
    Result<LineSocket> s = LineSocket::Connect(host_, port, options_.connect_timeout_s, 4096);
    if (!s.ok()) return RobotFailure(RobotErrorOf(s.status()), name_ + ": " + s.status().message());
    *socket = std::move(s).value();
    return Status::Ok();
  };
  if (Status s = open(&dashboard_, options_.dashboard_port); !s.ok()) return s;
  std::string greeting;
  if (LineIoResult io = dashboard_.ReadLine(&greeting, options_.reply_timeout_s); !io.ok()) {
    return RobotFailure(RobotErrorOfIo(io.outcome), name_ + ": the Dashboard server sent no greeting: " + io.error);
  }
  if (Status s = CheckDashboard(); !s.ok()) return s;
  if (Status s = open(&secondary_, options_.secondary_port); !s.ok()) return s;
  if (Status s = ReadKinematics(); !s.ok()) return s;
  identity_.backend = "ur";
  identity_.calibration_id = ur::CalibrationIdOf(*kinematics_);
  identity_.real_hardware = true;
  if (const std::string refusal = IdentityRefusal(identity_, first_identity_, options_.expected_identity, name_);
      !refusal.empty()) {
    return RobotFailure(RobotError::kProtocol, refusal);
  }
  if (Status s = open(&rtde_, options_.rtde_port); !s.ok()) return s;
  if (Status s = StartRtde(); !s.ok()) return s;
  StartReader();  // from here on both streams are read as they come, whatever the caller does
  return Status::Ok();
}

Status UrRobot::Connect() {
  if (link_ == Link::kUp) return Status::Ok();
  link_ = Link::kClosed;
  if (Status s = ConnectUnchecked(); !s.ok()) {
    CloseAll();  // nothing was sent to the arm: no movej, no stopj
    return s;
  }
  link_ = Link::kUp;
  broken_reason_.clear();
  const Status rest = CheckStartAtRest([this] { return ReadJoints(); }, [this](double s) { clock_.SleepFor(s); },
                                       options_.limits, options_.rest, name_);
  if (!rest.ok()) {
    CloseAll();
    link_ = Link::kClosed;
    return rest;
  }
  if (const RobotStatus now = ur::StatusOfState(last_state_); now.state != MotionState::kIdle) {
    CloseAll();
    link_ = Link::kClosed;
    return RobotFailure(now.state == MotionState::kProtectiveStop  ? RobotError::kProtectiveStop
                        : now.state == MotionState::kEmergencyStop ? RobotError::kEmergencyStop
                                                                   : RobotError::kRejected,
                        name_ + ": RTDE reports " + now.message + ": a person must clear it at the teach pendant");
  }
  if (last_state_.runtime_state != 1) {  // RTDE guide: 1 stopped; a script sent now would replace a program
    CloseAll();
    link_ = Link::kClosed;
    return RobotFailure(RobotError::kRejected, name_ + ": a program is running on the controller (RTDE runtime_state " +
                                                   std::to_string(last_state_.runtime_state) +
                                                   ", not 1 stopped): stop it at the teach pendant");
  }
  if (!first_identity_) first_identity_ = identity_;
  if (options_.log) {
    std::ostringstream said;
    said.precision(12);
    said << name_ << ": " << identity_.model << " serial " << identity_.serial << ", factory calibration "
         << identity_.calibration_id << " (status " << kinematics_->calibration_status
         << "); its standard DH table in a robot config's keys:";
    constexpr double kDegPerRad = 57.29577951308232;
    for (int j = 0; j < 6; ++j) {
      said << "\n  - {a_mm: " << kinematics_->dh_a[j] * 1e3 << ", alpha_deg: " << kinematics_->dh_alpha[j] * kDegPerRad
           << ", d_mm: " << kinematics_->dh_d[j] * 1e3 << ", theta_offset_deg: " << kinematics_->dh_theta[j] * kDegPerRad
           << "}";
    }
    options_.log(said.str());
  }
  return Status::Ok();
}

void UrRobot::Disconnect() {
  CloseAll();
  link_ = Link::kClosed;
}

Result<RobotIdentity> UrRobot::Identity() {
  if (Status link = LinkStatus("Identity"); !link.ok()) return link;
  return identity_;
}

Result<JointLimits> UrRobot::Limits() {
  if (Status link = LinkStatus("Limits"); !link.ok()) return link;
  return options_.limits;
}

Result<JointReading> UrRobot::ReadJoints() {
  if (Status link = LinkStatus("ReadJoints"); !link.ok()) return link;
  // A reading taken now: the next data package, not the one that arrived before the call (up to one RTDE
  // period old, which the session would count as a stale reading).
  double arrival_s = 0;
  Result<ur::UrState> state = LatestState(&arrival_s, clock_.Now());
  if (!state.ok()) return state.status();
  JointReading reading;
  reading.position_rad = state->q_rad;
  reading.velocity_rad_s = state->qd_rad_s;
  reading.time_s = arrival_s;
  return reading;
}

Status UrRobot::StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  if (Status link = LinkStatus("StartMove"); !link.ok()) return link;
  if (const std::string problem = CheckMoveTarget(options_.limits, target_rad, velocity_scaling); !problem.empty()) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + problem);
  }
  Result<ur::UrState> state = LatestState();
  if (!state.ok()) return state.status();
  if (const RobotStatus now = ur::StatusOfState(*state); now.state != MotionState::kIdle) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + now.message);
  }
  const double velocity = velocity_scaling * options_.limits.max_velocity_rad_s.minCoeff();
  const std::string script = ur::MovejScript(target_rad, options_.acceleration_per_velocity * velocity, velocity);
  if (LineIoResult io = secondary_.WriteLine(script, options_.reply_timeout_s); !io.ok()) {
    return Broken(RobotErrorOfIo(io.outcome), "secondary interface: movej not sent: " + io.error);
  }
  target_ = target_rad;
  return Status::Ok();
}

Result<RobotStatus> UrRobot::GetStatus() {
  if (Status link = LinkStatus("GetStatus"); !link.ok()) return link;
  Result<ur::UrState> state = LatestState();
  if (!state.ok()) return state.status();
  RobotStatus status = ur::StatusOfState(*state);
  if (status.state != MotionState::kIdle) {
    target_.reset();
    return status;
  }
  if (target_) {
    const bool still = state->qd_rad_s.cwiseAbs().maxCoeff() < options_.rest.velocity_rad_s;
    const bool there = (state->q_rad - *target_).cwiseAbs().maxCoeff() <= options_.target_tolerance_rad;
    if (still && there) {
      target_.reset();
    } else {
      status.state = MotionState::kMoving;
    }
  }
  return status;
}

Status UrRobot::Stop() {
  target_.reset();
  const std::string script = ur::StopjScript(options_.stop_deceleration_rad_s2);
  if (link_ == Link::kUp && secondary_.WriteLine(script, options_.reply_timeout_s).ok()) return Status::Ok();
  if (link_ == Link::kUp) {  // the Dashboard's stop: a second way
    Result<std::string> stopped = Dashboard("stop");
    if (stopped.ok() && Lower(*stopped).rfind("stopped", 0) == 0) return Status::Ok();
  }
  if (link_ == Link::kNeverConnected || link_ == Link::kClosed) return LinkStatus("Stop");
  // The link is lost: stopj on a fresh connection to the secondary interface (stopping is always safe).
  Result<LineSocket> fresh = LineSocket::Connect(host_, options_.secondary_port, options_.connect_timeout_s, 4096);
  if (fresh.ok()) {
    LineSocket socket = std::move(fresh).value();
    if (socket.WriteLine(script, options_.reply_timeout_s).ok()) return Status::Ok();
  }
  return RobotFailure(RobotError::kDisconnected,
                      name_ + ": Stop: stopj could not be sent (" + broken_reason_ + "): stop the arm at the pendant");
}

}  // namespace selfcal::robot
