#include "robot/ur_fake.h"

#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include "base/numbers.h"
#include "robot/clock.h"
#include "robot/fake_support.h"

namespace selfcal::robot {
namespace {

constexpr double kRtdeStep_s = 0.008;        // the RTDE stream at 125 Hz
constexpr double kRobotStatePeriod_s = 0.1;  // the secondary interface's robot state at 10 Hz

using Log = internal::FakeLog;
using internal::AcceptNewest;
using internal::Say;

}  // namespace

ur::KinematicsInfo Ur5eNominalKinematics() {
  ur::KinematicsInfo info;
  info.checksum = {0x1001, 0x1002, 0x1003, 0x1004, 0x1005, 0x1006};
  info.dh_theta = {0, 0, 0, 0, 0, 0};
  info.dh_a = {0, -0.425, -0.3922, 0, 0, 0};
  info.dh_d = {0.1625, 0, 0, 0.1333, 0.0997, 0.0996};
  info.dh_alpha = {kPi / 2, 0, 0, kPi / 2, -kPi / 2, 0};
  info.calibration_status = 1;
  return info;
}

UrFakeController::UrFakeController(const UrFakeOptions& options) : options_(options) {
  state_.q_rad = options_.start_rad;
  if (options_.protective_stop_at_start) state_.safety_status_bits = ur::kSafetyProtectiveStopped;
  if (options_.program_running) state_.runtime_state = 2;
}

Result<UrFakeController> UrFakeController::Listen(const UrFakeOptions& options) {
  UrFakeController fake(options);
  for (auto [listener, port] : {std::pair{&fake.rtde_, options.rtde_port}, std::pair{&fake.secondary_, options.secondary_port},
                                std::pair{&fake.dashboard_, options.dashboard_port}}) {
    Result<TcpListener> l = TcpListener::Listen("127.0.0.1", port);
    if (!l.ok()) return l.status();
    *listener = std::move(l).value();
  }
  return fake;
}

void UrFakeController::DropAll(const Log& log) {
  rtde_client_.Close();
  secondary_client_.Close();
  dashboard_client_.Close();
  streaming_ = false;
  Say(log, "fault: every connection closed during move #" + std::to_string(moves_ - 1));
}

void UrFakeController::Step(double dt_s, const Log& log) {
  if (!moving_) {
    state_.qd_rad_s.setZero();
    if (!options_.program_running) state_.runtime_state = 1;
    return;
  }
  move_time_s_ += dt_s;
  const double fraction = move_duration_s_ > 0 ? std::min(1.0, move_time_s_ / move_duration_s_) : 1.0;
  const int move = moves_ - 1;
  if (fraction >= 0.5 && (move == options_.protective_stop_move || move == options_.stall_move)) {
    state_.q_rad = from_ + 0.5 * (target_ - from_);
    moving_ = false;
    state_.qd_rad_s.setZero();
    if (move == options_.protective_stop_move) {
      state_.safety_status_bits = ur::kSafetyProtectiveStopped;
      state_.runtime_state = 1;
      Say(log, "fault: protective stop half way through move #" + std::to_string(move));
    } else {
      Say(log, "fault: move #" + std::to_string(move) + " stops half way and never finishes");
    }
    options_.protective_stop_move = options_.stall_move = -1;
    return;
  }
  if (fraction >= 0.5 && move == options_.drop_move) {
    options_.drop_move = -1;
    DropAll(log);  // the program keeps running on a real controller: the arm goes on to its target
  }
  state_.q_rad = from_ + fraction * (target_ - from_);
  state_.qd_rad_s = fraction < 1 ? ((target_ - from_) / move_duration_s_).eval() : Eigen::Matrix<double, 6, 1>::Zero().eval();
  state_.runtime_state = fraction < 1 ? 2 : 1;
  if (fraction >= 1) moving_ = false;
}

void UrFakeController::ServeRtde(const Log& log) {
  while (rtde_client_.is_open()) {
    std::string header, payload;
    LineIoResult io = rtde_client_.ReadBytes(&header, 3, 0);
    if (io.outcome == LineIo::kTimeout) return;
    Result<uint16_t> size = io.ok() ? ur::RtdePackageSize(header) : Result<uint16_t>(uint16_t{3});
    if (io.ok() && size.ok()) io = rtde_client_.ReadBytes(&payload, *size - 3, 0.5);
    if (!io.ok() || !size.ok()) {
      rtde_client_.Close();
      streaming_ = false;
      return;
    }
    const uint8_t type = static_cast<uint8_t>(header[2]);
    std::string reply;
    if (type == ur::kRtdeRequestProtocolVersion) {
      const bool two = payload.size() == 2 && payload[0] == 0 && payload[1] == 2;
      reply = ur::EncodeRtde(type, std::string(1, two ? 1 : 0));
      Say(log, "rtde: protocol version request");
    } else if (type == ur::kRtdeSetupOutputs && payload.size() >= 8) {
      static const std::map<std::string, std::string> kTypes = {
          {"actual_q", "VECTOR6D"}, {"actual_qd", "VECTOR6D"}, {"runtime_state", "UINT32"},
          {"safety_status_bits", "UINT32"}, {"robot_status_bits", "UINT32"}};
      std::string types, names = payload.substr(8);
      for (size_t at = 0; at <= names.size();) {
        const size_t comma = std::min(names.find(',', at), names.size());
        const std::string name = names.substr(at, comma - at);
        const auto found = kTypes.find(name);
        const bool missing = found == kTypes.end() || (options_.wrong_recipe && name == "safety_status_bits");
        types += (types.empty() ? "" : ",") + (missing ? std::string("NOT_FOUND") : found->second);
        at = comma + 1;
      }
      reply = ur::EncodeRtde(type, std::string(1, 1) + types);
      Say(log, "rtde: output recipe " + names + " -> " + types);
    } else if (type == ur::kRtdeStart || type == ur::kRtdePause) {
      streaming_ = type == ur::kRtdeStart;
      reply = ur::EncodeRtde(type, std::string(1, 1));
      Say(log, streaming_ ? "rtde: start" : "rtde: pause");
    } else {
      reply = ur::EncodeRtde(ur::kRtdeTextMessage, "unknown package");
    }
    rtde_client_.WriteBytes(reply, 0.5);
  }
}

void UrFakeController::ServeSecondary(const Log& log) {
  std::string line;
  while (secondary_client_.is_open()) {
    const LineIoResult io = secondary_client_.ReadLine(&line, 0);
    if (io.outcome == LineIo::kTimeout) return;
    if (!io.ok()) {
      secondary_client_.Close();
      return;
    }
    Say(log, "secondary: " + line);
    double velocity = 0;
    if (line.rfind("stopj(", 0) == 0) {
      ++stop_commands_;
      moving_ = false;
      continue;
    }
    const std::optional<Eigen::VectorXd> q = ur::ParseMovej(line, &velocity);
    if (!q) continue;  // a real controller would raise a script error; the fake ignores it
    ++motion_commands_;
    if (options_.remote_control_off || state_.safety_status_bits != ur::kSafetyNormal) {
      Say(log, "ignored: not in remote control or not in normal safety status");
      continue;
    }
    from_ = state_.q_rad;
    target_ = *q;
    velocity_ = velocity;
    move_duration_s_ = (target_ - from_).cwiseAbs().maxCoeff() / velocity_;
    move_time_s_ = 0;
    moving_ = true;
    ++moves_;
  }
}

void UrFakeController::ServeDashboard(const Log& log) {
  std::string line;
  while (dashboard_client_.is_open()) {
    const LineIoResult io = dashboard_client_.ReadLine(&line, 0);
    if (io.outcome == LineIo::kTimeout) return;
    if (!io.ok()) {
      dashboard_client_.Close();
      return;
    }
    Say(log, "dashboard: " + line);
    std::string reply;
    const bool stopped = state_.safety_status_bits & ur::kSafetyProtectiveStopped;
    if (line == "is in remote control") {
      reply = options_.remote_control_off ? "false" : "true";
    } else if (line == "safetystatus") {
      reply = std::string("Safetystatus: ") + (stopped ? "PROTECTIVE_STOP" : "NORMAL");
    } else if (line == "robotmode") {
      reply = "Robotmode: RUNNING";
    } else if (line == "get_robot_model") {
      reply = options_.model;
    } else if (line == "get_serial_number") {
      reply = options_.serial;
    } else if (line == "unlock protective stop") {  // a person at the pendant, after inspecting the cause
      state_.safety_status_bits = ur::kSafetyNormal;
      reply = "Protective stop releasing";
    } else if (line == "stop") {
      ++stop_commands_;
      moving_ = false;
      reply = "Stopped";
    } else {
      reply = "could not understand: '" + line + "'";
    }
    dashboard_client_.WriteLine(reply, 0.5);
  }
}

void UrFakeController::Serve(const std::atomic<bool>& stop, const Log& log) {
  MonotonicClock clock;
  double next_s = clock.Now();
  while (!stop.load()) {
    ServeClients(log);
    Step(kRtdeStep_s, log);
    since_robot_state_s_ += kRtdeStep_s;
    if (secondary_client_.is_open() && since_robot_state_s_ >= kRobotStatePeriod_s) {
      since_robot_state_s_ = 0;
      if (!secondary_client_.WriteBytes(ur::EncodeRobotStateMessage(options_.kinematics), 0.5).ok()) {
        secondary_client_.Close();
      }
    }
    if (streaming_ && rtde_client_.is_open()) {
      const std::string package = ur::EncodeRtde(ur::kRtdeDataPackage, ur::EncodeStateData(1, state_));
      if (!rtde_client_.WriteBytes(package, 0.5).ok()) rtde_client_.Close();
    }
    next_s += kRtdeStep_s;
    clock.SleepFor(std::max(0.0, next_s - clock.Now()));
  }
  ServeClients(log);  // what arrived before the stop (a client's last stopj) is counted, as a controller would
}

void UrFakeController::ServeClients(const Log& log) {
  AcceptNewest(&dashboard_, &dashboard_client_, "Connected: Universal Robots Dashboard Server");
  AcceptNewest(&secondary_, &secondary_client_);
  if (AcceptNewest(&rtde_, &rtde_client_)) streaming_ = false;
  ServeDashboard(log);
  ServeSecondary(log);
  ServeRtde(log);
}

}  // namespace selfcal::robot
