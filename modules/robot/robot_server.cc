#include "robot/robot_server.h"

#include <optional>
#include <ostream>
#include <utility>

namespace selfcal::robot {

using protocol::RequestKind;

RobotServer::RobotServer(Robot& robot, RobotServerOptions options) : robot_(robot), options_(std::move(options)) {}

Status RobotServer::Listen() {
  Result<TcpListener> listener = TcpListener::Listen(options_.address, options_.port);
  if (!listener.ok()) return listener.status();
  listener_ = std::move(listener).value();
  return Status::Ok();
}

void RobotServer::Log(const std::string& line) {
  if (options_.log != nullptr) *options_.log << "robot server: " << line << std::endl;
}

void RobotServer::EndClient(LineSocket& client, const std::string& why) {
  client.Close();
  if (!hello_done_) {  // it could not have commanded anything
    Log("client gone (" + why + ")");
    return;
  }
  hello_done_ = false;
  const Status stop = robot_.Stop();  // the arm never moves without a client watching it
  Log("client gone (" + why + ")" + (stop.ok() ? "; robot stopped" : "; stop: " + stop.message()));
}

Status RobotServer::Serve(const std::atomic<bool>& stop) {
  if (!listener_.is_open()) return Status::Error(ErrorCode::kInvalidInput, "robot server: Serve() before Listen()");
  std::optional<LineSocket> client;
  while (!stop.load()) {
    if (!client) {
      client = listener_.Accept(options_.poll_interval_s, options_.max_line_bytes);
      if (client) Log("client connected");
      continue;
    }
    if (std::optional<LineSocket> other = listener_.Accept(0, options_.max_line_bytes)) {
      other->WriteLine(protocol::ErrorReply(protocol::kErrFault, "busy: another client is connected"),
                       options_.poll_interval_s);
      Log("refused a second client");
    }
    std::string line;
    const LineIoResult read = client->ReadLine(&line, options_.poll_interval_s);
    if (read.outcome == LineIo::kTimeout) continue;
    if (read.outcome == LineIo::kTooLong) {
      client->WriteLine(protocol::ErrorReply(protocol::kErrBadRequest, "line too long"), options_.poll_interval_s);
    }
    if (!read.ok()) {
      EndClient(*client, read.error);
      client.reset();
      continue;
    }
    bool close_client = false;
    const std::string reply = Handle(line, &close_client);
    if (!reply.empty() && !client->WriteLine(reply, options_.poll_interval_s + 1.0).ok()) close_client = true;
    if (close_client) {
      EndClient(*client, "closed by the server after \"" + line.substr(0, 60) + "\"");
      client.reset();
    }
  }
  if (client) EndClient(*client, "server stopping");
  listener_.Close();
  return Status::Ok();
}

std::string RobotServer::Failure(const Status& status, bool* close_client) {
  const RobotError error = RobotErrorOf(status);
  if (error == RobotError::kDisconnected) {  // R10: the robot is gone, so is the client's connection
    *close_client = true;
    return "";
  }
  return protocol::ErrorReply(protocol::ErrorCodeFor(error), status.message());
}

std::string RobotServer::Handle(const std::string& line, bool* close_client) {
  const Result<protocol::Request> request = protocol::ParseRequest(line);
  if (!request.ok()) return protocol::ErrorReply(protocol::kErrBadRequest, request.status().message());
  switch (request->kind) {
    case RequestKind::kBye:
      *close_client = true;
      return protocol::OkReply();
    case RequestKind::kHello: {
      if (Status connect = robot_.Connect(); !connect.ok()) return Failure(connect, close_client);
      const Result<RobotIdentity> identity = robot_.Identity();
      if (!identity.ok()) return Failure(identity.status(), close_client);
      const Result<JointLimits> limits = robot_.Limits();
      if (!limits.ok()) return Failure(limits.status(), close_client);
      hello_done_ = true;
      return protocol::HelloReply(*identity, static_cast<int>(limits->lower_rad.size()));
    }
    default:
      break;
  }
  if (!hello_done_) return protocol::ErrorReply(protocol::kErrBadRequest, "send HELLO first");
  switch (request->kind) {
    case RequestKind::kLimits: {
      const Result<JointLimits> limits = robot_.Limits();
      return limits.ok() ? protocol::LimitsReply(*limits) : Failure(limits.status(), close_client);
    }
    case RequestKind::kJoints: {
      const Result<JointReading> reading = robot_.ReadJoints();
      return reading.ok() ? protocol::JointsReply(*reading) : Failure(reading.status(), close_client);
    }
    case RequestKind::kMove: {
      const Status started = robot_.StartMove(request->target_rad, request->velocity_scaling);
      if (!started.ok()) return Failure(started, close_client);
      if (options_.drop_client_after_moves.count(moves_served_) > 0) {
        Log("dropping the client after move #" + std::to_string(moves_served_) + " (test hook)");
        *close_client = true;
      }
      ++moves_served_;
      return protocol::OkReply();
    }
    case RequestKind::kStatus: {
      const Result<RobotStatus> status = robot_.GetStatus();
      return status.ok() ? protocol::StatusReply(*status) : Failure(status.status(), close_client);
    }
    case RequestKind::kStop: {
      const Status stopped = robot_.Stop();
      return stopped.ok() ? protocol::OkReply() : Failure(stopped, close_client);
    }
    case RequestKind::kHello:
    case RequestKind::kBye:
      break;
  }
  return protocol::ErrorReply(protocol::kErrBadRequest, "unexpected request");
}

}  // namespace selfcal::robot
