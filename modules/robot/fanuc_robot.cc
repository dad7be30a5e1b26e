#include "robot/fanuc_robot.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <utility>

#include "base/terminal_text.h"

namespace selfcal::robot {
namespace {

using fanuc::PacketKind;

constexpr size_t kMaxPacketBytes = 4096;

LineIoResult Send(LineSocket* socket, const std::string& packet, double timeout_s) {
  return socket->WriteBytes(packet + "\r\n", timeout_s);  // RMI packets end with CR LF
}

}  // namespace

Status FanucRobotOptions::Validate() const {
  std::ostringstream problems;
  if (connect_port < 1 || connect_port > 65535) problems << " port " << connect_port << " must lie in 1-65535;";
  if (!(connect_timeout_s > 0 && reply_timeout_s > 0 && std::isfinite(connect_timeout_s) && std::isfinite(reply_timeout_s))) {
    problems << " timeouts must be finite and > 0;";
  }
  if (limits.lower_rad.size() != 6) problems << " limits must give the six joints of the arm;";
  if (const std::string bad = limits.lower_rad.size() == 6 ? CheckJointLimits(limits) : ""; !bad.empty()) {
    problems << " " << bad << ";";
  }
  if (!(rest.interval_s >= 0 && rest.interval_s <= 1 && rest.tolerance_rad > 0 && rest.velocity_rad_s > 0 &&
        target_tolerance_rad > 0)) {
    problems << " rest and tolerance settings must be > 0;";
  }
  if (problems.str().empty()) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput, "FANUC robot options:" + problems.str());
}

Result<FanucRobotOptions> FanucRunOptions(const std::string& address, JointLimits position_limits, std::string* host) {
  FanucRobotOptions options;
  const size_t colon = address.find(':');
  const bool one_colon = colon != std::string::npos && address.find(':', colon + 1) == std::string::npos;
  *host = one_colon ? address.substr(0, colon) : address;
  if (one_colon) {
    const std::string port = address.substr(colon + 1);
    const bool digits = !port.empty() && port.size() <= 5 && std::all_of(port.begin(), port.end(), ::isdigit);
    options.connect_port = digits ? std::stoi(port) : -1;
  }
  if (host->empty() || options.connect_port < 1 || options.connect_port > 65535) {
    return Status::Error(ErrorCode::kInvalidInput, "--address \"" + address + "\": --backend fanuc takes the controller's "
                                                   "HOST or HOST:PORT (PORT the RMI connect port, 16001 by default)");
  }
  position_limits.max_velocity_rad_s =
      Eigen::VectorXd::Constant(position_limits.lower_rad.size(), kFanucJointSpeedLimit_rad_s);
  options.limits = std::move(position_limits);
  if (Status valid = options.Validate(); !valid.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, valid.message() + " (the robot config must describe a six-joint arm)");
  }
  return options;
}

FanucRobot::FanucRobot(std::string host, FanucRobotOptions options)
    : host_(std::move(host)), options_(std::move(options)),
      name_("FANUC robot " + host_ + ":" + std::to_string(options_.connect_port)) {
  const Status valid = options_.Validate();
  SELFCAL_CHECK(valid.ok(), valid.message());
}

FanucRobot::~FanucRobot() { Disconnect(); }

void FanucRobot::Close() {
  socket_.Close();
  target_.reset();
  pending_sequence_.reset();
}

Status FanucRobot::LinkStatus(const char* call) const {
  if (link_ == Link::kUp) return Status::Ok();
  if (link_ == Link::kBroken) {
    return RobotFailure(RobotError::kDisconnected,
                        name_ + ": " + call + ": the connection was lost (" + broken_reason_ + "); Connect() again");
  }
  return RobotFailure(RobotError::kNotConnected, name_ + ": " + call + ": not connected");
}

Status FanucRobot::Broken(RobotError error, const std::string& reason) {
  Close();
  if (link_ == Link::kUp) {
    link_ = Link::kBroken;
    broken_reason_ = reason;
  }
  return RobotFailure(error, name_ + ": " + reason);
}

Status FanucRobot::Note(const fanuc::Packet& packet) {
  if (packet.kind == PacketKind::kCommunication && packet.name == "FRC_Terminate") {
    return Broken(RobotError::kDisconnected, "the controller ended the session (FRC_Terminate)");
  }
  if (packet.kind == PacketKind::kCommunication && packet.name == "FRC_SystemFault") {
    system_fault_ = "the controller reports a system fault (FRC_SystemFault, sequence " +
                    std::to_string(packet.sequence_id.value_or(-1)) + "): read the alarm at the teach pendant";
    return Status::Ok();
  }
  if (packet.kind == PacketKind::kInstruction && pending_sequence_ && packet.sequence_id == pending_sequence_) {
    pending_answered_ = true;
    pending_error_ = packet.error_id;
    return Status::Ok();
  }
  if (packet.kind == PacketKind::kInstruction) return Status::Ok();  // an answer to a move already given up
  return Broken(RobotError::kProtocol, "RMI: an unexpected " + TerminalSafe(packet.name) + " packet");
}

Result<fanuc::Packet> FanucRobot::Ask(PacketKind kind, const std::string& name, const std::string& request) {
  if (LineIoResult io = Send(&socket_, request, options_.reply_timeout_s); !io.ok()) {
    return Broken(RobotErrorOfIo(io.outcome), "RMI: " + name + " not sent: " + io.error);
  }
  const double deadline_s = clock_.Now() + options_.reply_timeout_s;
  while (true) {
    std::string line;
    const LineIoResult io = socket_.ReadLine(&line, std::max(0.0, deadline_s - clock_.Now()));
    if (!io.ok()) {
      return Broken(RobotErrorOfIo(io.outcome),
                    "RMI (port " + std::to_string(session_port_) + "): no answer to " + name + ": " + io.error);
    }
    Result<fanuc::Packet> packet = fanuc::ParsePacket(line);
    if (!packet.ok()) return Broken(RobotError::kProtocol, packet.status().message());
    if (packet->kind == kind && packet->name == name) return packet;
    if (packet->kind == PacketKind::kCommand || packet->name == "Unknown") {
      return Broken(RobotError::kProtocol, "RMI: " + name + " was answered with " + TerminalSafe(packet->name));
    }
    if (Status noted = Note(*packet); !noted.ok()) return noted;
  }
}

Result<fanuc::ControllerStatus> FanucRobot::ControllerState() {
  Result<fanuc::Packet> reply = Ask(PacketKind::kCommand, "FRC_GetStatus", fanuc::SimpleRequest(PacketKind::kCommand, "FRC_GetStatus"));
  if (!reply.ok()) return reply.status();
  if (reply->error_id != 0 || !reply->status) {
    return Broken(RobotError::kProtocol, "RMI: FRC_GetStatus answered ErrorID " + std::to_string(reply->error_id));
  }
  return *reply->status;
}

Result<fanuc::Packet> FanucRobot::SessionPort() {
  Result<LineSocket> s = LineSocket::Connect(host_, options_.connect_port, options_.connect_timeout_s, kMaxPacketBytes);
  if (!s.ok()) return RobotFailure(RobotErrorOf(s.status()), name_ + ": " + s.status().message());
  LineSocket startup = std::move(s).value();
  std::string line;
  LineIoResult io = Send(&startup, fanuc::SimpleRequest(PacketKind::kCommunication, "FRC_Connect"), options_.reply_timeout_s);
  if (io.ok()) io = startup.ReadLine(&line, options_.reply_timeout_s);
  if (!io.ok()) return RobotFailure(RobotErrorOfIo(io.outcome), name_ + ": no answer to FRC_Connect: " + io.error);
  Result<fanuc::Packet> reply = fanuc::ParsePacket(line);
  if (!reply.ok()) return RobotFailure(RobotError::kProtocol, name_ + ": " + reply.status().message());
  if (reply->name != "FRC_Connect" || reply->error_id != 0 || !reply->port) {
    return RobotFailure(RobotError::kRejected, name_ + ": FRC_Connect refused (ErrorID " + std::to_string(reply->error_id) +
                                                   "): another client holds RMI, or the RMI option is not running");
  }
  return reply;
}

Status FanucRobot::CheckIdentity() {
  identity_.backend = "fanuc";
  identity_.serial = host_ + ":" + std::to_string(options_.connect_port);
  identity_.calibration_id = "";
  identity_.real_hardware = true;
  if (const std::string refusal = IdentityRefusal(identity_, first_identity_, options_.expected_identity, name_);
      !refusal.empty()) {
    return RobotFailure(RobotError::kProtocol, refusal);
  }
  return Status::Ok();
}

Status FanucRobot::ConnectUnchecked() {
  Result<fanuc::Packet> connected = SessionPort();
  if (!connected.ok()) return connected.status();
  session_port_ = *connected->port;
  identity_.model = "FANUC RMI " + std::to_string(connected->major_version) + "." + std::to_string(connected->minor_version);
  Result<LineSocket> s = LineSocket::Connect(host_, session_port_, options_.connect_timeout_s, kMaxPacketBytes);
  if (!s.ok()) return RobotFailure(RobotErrorOf(s.status()), name_ + ": " + s.status().message());
  socket_ = std::move(s).value();
  link_ = Link::kUp;  // for Ask; Connect() closes it again on any refusal
  Result<fanuc::ControllerStatus> status = ControllerState();
  if (!status.ok()) return status.status();
  if (const RobotStatus now = fanuc::StatusOf(*status); now.state != MotionState::kIdle) {
    return RobotFailure(RobotError::kRejected, name_ + ": " + now.message + ": a person must clear it at the teach pendant");
  }
  if (status->program_status != 0 || status->rmi_motion_status != 0) {
    return RobotFailure(RobotError::kRejected, name_ + ": a program is running on the controller (FRC_GetStatus "
                                                       "ProgramStatus " + std::to_string(status->program_status) +
                                                       ", RMIMotionStatus " + std::to_string(status->rmi_motion_status) +
                                                       "): abort it at the teach pendant");
  }
  if (Status s2 = CheckIdentity(); !s2.ok()) return s2;
  last_reading_.reset();
  const Status rest = CheckStartAtRest([this] { return ReadJoints(); }, [this](double t) { clock_.SleepFor(t); },
                                       options_.limits, options_.rest, name_);
  if (!rest.ok()) return rest;
  initialized_ = false;  // FRC_Initialize before the first move: a dry run leaves RMI as it found it
  return Status::Ok();
}

Status FanucRobot::Initialize() {
  Result<fanuc::Packet> init = Ask(PacketKind::kCommand, "FRC_Initialize", fanuc::SimpleRequest(PacketKind::kCommand, "FRC_Initialize"));
  if (!init.ok()) return init.status();
  if (init->error_id != 0) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: FRC_Initialize refused (ErrorID " +
                                                   std::to_string(init->error_id) + "): read the alarm at the teach pendant");
  }
  initialized_ = true;
  next_sequence_id_ = 1;
  return Status::Ok();
}

Status FanucRobot::Connect() {
  if (link_ == Link::kUp) return Status::Ok();
  link_ = Link::kClosed;
  system_fault_.clear();
  if (Status s = ConnectUnchecked(); !s.ok()) {
    Close();  // no instruction was sent: nothing can have moved
    link_ = Link::kClosed;
    return s;
  }
  broken_reason_.clear();
  if (!first_identity_) first_identity_ = identity_;
  if (options_.log) {
    options_.log(name_ + ": " + identity_.model + " on session port " + std::to_string(session_port_) +
                 "; RMI reports no serial number and no mastering data: the session records the controller's address");
  }
  return Status::Ok();
}

void FanucRobot::Disconnect() {
  if (link_ == Link::kUp) {  // the polite end (2.2.2); its answer is not awaited
    Send(&socket_, fanuc::SimpleRequest(PacketKind::kCommunication, "FRC_Disconnect"), options_.reply_timeout_s);
  }
  Close();
  link_ = Link::kClosed;
}

Result<RobotIdentity> FanucRobot::Identity() {
  if (Status link = LinkStatus("Identity"); !link.ok()) return link;
  return identity_;
}

Result<JointLimits> FanucRobot::Limits() {
  if (Status link = LinkStatus("Limits"); !link.ok()) return link;
  return options_.limits;
}

Result<JointReading> FanucRobot::ReadJoints() {
  if (Status link = LinkStatus("ReadJoints"); !link.ok()) return link;
  Result<fanuc::Packet> reply =
      Ask(PacketKind::kCommand, "FRC_ReadJointAngles", fanuc::SimpleRequest(PacketKind::kCommand, "FRC_ReadJointAngles"));
  if (!reply.ok()) return reply.status();
  if (reply->error_id != 0 || !reply->joints_rad) {
    return Broken(RobotError::kProtocol, "RMI: FRC_ReadJointAngles answered ErrorID " + std::to_string(reply->error_id));
  }
  JointReading reading;
  reading.position_rad = *reply->joints_rad;
  reading.time_s = clock_.Now();
  reading.velocity_rad_s = Eigen::VectorXd::Zero(reading.position_rad.size());
  if (last_reading_ && reading.time_s - last_reading_->time_s > 1e-3 && reading.time_s - last_reading_->time_s < 0.5) {
    reading.velocity_rad_s = (reading.position_rad - last_reading_->position_rad) / (reading.time_s - last_reading_->time_s);
  }
  last_reading_ = reading;
  return reading;
}

Status FanucRobot::StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  if (Status link = LinkStatus("StartMove"); !link.ok()) return link;
  if (const std::string problem = CheckMoveTarget(options_.limits, target_rad, velocity_scaling); !problem.empty()) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + problem);
  }
  if (target_) return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: a move is in progress");
  Result<fanuc::ControllerStatus> state = ControllerState();
  if (!state.ok()) return state.status();
  if (!system_fault_.empty()) return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + system_fault_);
  if (const RobotStatus now = fanuc::StatusOf(*state); now.state != MotionState::kIdle) {
    return RobotFailure(RobotError::kRejected, name_ + ": move refused before sending: " + now.message);
  }
  if (Status init = initialized_ ? Status::Ok() : Initialize(); !init.ok()) return init;
  const int percent = std::clamp(static_cast<int>(std::lround(velocity_scaling * 100)), 1, 100);
  const int sequence = next_sequence_id_++;
  if (LineIoResult io = Send(&socket_, fanuc::JointMotionRequest(sequence, target_rad, percent), options_.reply_timeout_s);
      !io.ok()) {
    return Broken(RobotErrorOfIo(io.outcome), "RMI: FRC_JointMotionJRep not sent: " + io.error);
  }
  pending_sequence_ = sequence;
  pending_answered_ = false;
  pending_error_ = 0;
  target_ = target_rad;
  return Status::Ok();
}

Result<RobotStatus> FanucRobot::GetStatus() {
  if (Status link = LinkStatus("GetStatus"); !link.ok()) return link;
  Result<fanuc::ControllerStatus> state = ControllerState();
  if (!state.ok()) return state.status();
  RobotStatus status = fanuc::StatusOf(*state);
  if (status.state == MotionState::kIdle && !system_fault_.empty()) status = {MotionState::kFault, system_fault_};
  if (status.state == MotionState::kIdle && target_ && pending_answered_ && pending_error_ != 0) {
    status = {MotionState::kFault, "FRC_JointMotionJRep was answered with ErrorID " + std::to_string(pending_error_)};
  }
  if (status.state != MotionState::kIdle) {
    target_.reset();
    return status;
  }
  if (target_) {
    Result<JointReading> now = ReadJoints();
    if (!now.ok()) return now.status();
    const bool there = (now->position_rad - *target_).cwiseAbs().maxCoeff() <= options_.target_tolerance_rad;
    if (pending_answered_ && there) {
      target_.reset();
      pending_sequence_.reset();
    } else {
      status.state = MotionState::kMoving;
    }
  }
  return status;
}

Status FanucRobot::Stop() {
  target_.reset();
  const std::string abort = fanuc::SimpleRequest(PacketKind::kCommand, "FRC_Abort");
  if (link_ == Link::kUp && Ask(PacketKind::kCommand, "FRC_Abort", abort).ok()) {
    pending_sequence_.reset();
    return Status::Ok();
  }
  if (link_ == Link::kNeverConnected || link_ == Link::kClosed) return LinkStatus("Stop");
  // The link is lost: FRC_Abort on a fresh session (stopping is always safe).
  Result<fanuc::Packet> connected = SessionPort();
  Result<LineSocket> fresh = connected.ok()
                                 ? LineSocket::Connect(host_, *connected->port, options_.connect_timeout_s, kMaxPacketBytes)
                                 : Result<LineSocket>(connected.status());
  if (!fresh.ok()) {
    return RobotFailure(RobotError::kDisconnected, name_ + ": Stop: FRC_Abort could not be sent (" + broken_reason_ +
                                                       "): stop the arm at the pendant");
  }
  LineSocket socket = std::move(fresh).value();
  if (!Send(&socket, abort, options_.reply_timeout_s).ok()) {
    return RobotFailure(RobotError::kDisconnected, name_ + ": Stop: FRC_Abort could not be sent on a new session (" +
                                                       broken_reason_ + "): stop the arm at the pendant");
  }
  return AbortAnswer(&socket);
}

// The answer to an FRC_Abort sent on a fresh session: only an answer with ErrorID 0 says the arm was stopped.
Status FanucRobot::AbortAnswer(LineSocket* socket) {
  const double deadline_s = clock_.Now() + options_.reply_timeout_s;
  const std::string sent = name_ + ": Stop: FRC_Abort was sent on a new session after the link was lost (" +
                           broken_reason_ + ") but ";
  while (true) {
    std::string line;
    const double left_s = deadline_s - clock_.Now();
    const LineIoResult io = left_s > 0 ? socket->ReadLine(&line, left_s) : LineIoResult{};
    if (left_s <= 0 || !io.ok()) {
      const std::string why = left_s <= 0 ? "no answer within the reply timeout" : io.error;
      return RobotFailure(RobotError::kDisconnected,
                          sent + "not acknowledged (" + why + "): make sure the arm stopped, at the pendant");
    }
    Result<fanuc::Packet> packet = fanuc::ParsePacket(line);
    if (!packet.ok() || packet->kind != PacketKind::kCommand || packet->name != "FRC_Abort") continue;
    if (packet->error_id == 0) return Status::Ok();
    return RobotFailure(RobotError::kRejected, sent + "refused with ErrorID " + std::to_string(packet->error_id) +
                                                   ": stop the arm at the pendant");
  }
}

}  // namespace selfcal::robot
