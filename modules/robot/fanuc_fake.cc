#include "robot/fanuc_fake.h"

#include <algorithm>
#include <utility>

#include "robot/clock.h"
#include "robot/fake_support.h"
#include "robot/fanuc_robot.h"

namespace selfcal::robot {
namespace {

constexpr double kStep_s = 0.008;
using Log = internal::FakeLog;
using fanuc::PacketKind;
using internal::AcceptNewest;
using internal::Say;

}  // namespace

FanucFakeController::FanucFakeController(const FanucFakeOptions& options) : options_(options) {
  q_ = options_.start_rad;
  status_.servo_ready = options_.servo_off_at_start ? 0 : 1;
  status_.tp_mode = options_.teach_pendant_enabled ? 1 : 0;
  status_.override_percent = 100;
}

Result<FanucFakeController> FanucFakeController::Listen(const FanucFakeOptions& options) {
  FanucFakeController fake(options);
  for (auto [listener, port] : {std::pair{&fake.connect_, options.connect_port}, std::pair{&fake.session_, 0}}) {
    Result<TcpListener> l = TcpListener::Listen("127.0.0.1", port);
    if (!l.ok()) return l.status();
    *listener = std::move(l).value();
  }
  return fake;
}

void FanucFakeController::Send(const std::string& packet) {
  if (session_client_.is_open() && !session_client_.WriteBytes(packet + "\r\n", 0.5).ok()) session_client_.Close();
}

void FanucFakeController::Step(double dt_s, const Log& log) {
  if (!moving_) return;
  move_time_s_ += dt_s;
  const double fraction = move_duration_s_ > 0 ? std::min(1.0, move_time_s_ / move_duration_s_) : 1.0;
  const int move = moves_ - 1;
  if (fraction >= 0.5 && (move == options_.servo_off_move || move == options_.stall_move)) {
    q_ = from_ + 0.5 * (target_ - from_);
    moving_ = false;
    if (move == options_.servo_off_move) {
      status_.servo_ready = 0;
      status_.rmi_motion_status = 0;
      Send(fanuc::SystemFault(sequence_));
      Send(fanuc::Reply(PacketKind::kInstruction, "FRC_JointMotionJRep", 2556955, sequence_));
      Say(log, "fault: the servos off half way through move #" + std::to_string(move));
    } else {
      Say(log, "fault: move #" + std::to_string(move) + " stops half way and never finishes");
    }
    options_.servo_off_move = options_.stall_move = -1;
    return;
  }
  if (fraction >= 0.5 && move == options_.wrong_answer_move) {
    options_.wrong_answer_move = -1;
    wrong_answer_now_ = true;
    Say(log, "fault: the next FRC_ReadJointAngles is answered as FRC_ReadCartesianPosition");
  }
  if (fraction >= 0.5 && move == options_.drop_move) {
    options_.drop_move = -1;
    session_client_.Close();  // the instruction keeps running: the arm goes on to its target
    Say(log, "fault: the session connection closed during move #" + std::to_string(move));
  }
  q_ = from_ + fraction * (target_ - from_);
  if (fraction >= 1) {
    moving_ = false;
    status_.next_sequence_id = sequence_ + 1;
    Send(fanuc::Reply(PacketKind::kInstruction, "FRC_JointMotionJRep", 0, sequence_));
  }
}

void FanucFakeController::ServeConnect(const Log& log) {
  std::string line;
  while (connect_client_.is_open()) {
    const LineIoResult io = connect_client_.ReadLine(&line, 0);
    if (io.outcome == LineIo::kTimeout) return;
    if (!io.ok()) {
      connect_client_.Close();
      return;
    }
    Say(log, "connect: " + line);
    Result<fanuc::Packet> packet = fanuc::ParsePacket(line);
    if (packet.ok() && packet->name == "FRC_Connect") {
      connect_client_.WriteBytes(fanuc::ConnectReply(0, session_.port(), 1, 0) + "\r\n", 0.5);
    } else {
      connect_client_.WriteBytes(fanuc::Reply(PacketKind::kCommand, "Unknown", 2556929) + "\r\n", 0.5);
    }
  }
}

std::string FanucFakeController::Answer(const fanuc::Packet& packet, const std::string& line, const Log& log) {
  const std::string& name = packet.name;
  if (name == "FRC_GetStatus") return fanuc::StatusReply(status_);
  if (name == "FRC_ReadJointAngles") {
    if (wrong_answer_now_) {
      wrong_answer_now_ = false;
      return fanuc::Reply(PacketKind::kCommand, "FRC_ReadCartesianPosition", 0);
    }
    return fanuc::JointAnglesReply(q_, ++time_tag_);
  }
  if (name == "FRC_Initialize") {
    const bool ok = status_.servo_ready == 1 && status_.tp_mode == 0 && status_.rmi_motion_status == 0;
    if (ok) status_.rmi_motion_status = 1;
    if (ok) status_.next_sequence_id = 1;
    return fanuc::Reply(PacketKind::kCommand, name, ok ? 0 : 2556950);
  }
  if (name == "FRC_Abort") {
    ++stop_commands_;
    moving_ = false;
    status_.rmi_motion_status = 0;
    if (options_.silent_abort) return "";
    return fanuc::Reply(PacketKind::kCommand, name, 0);
  }
  if (name == "FRC_Reset") return fanuc::Reply(PacketKind::kCommand, name, 0);
  if (name == "FRC_Disconnect") {
    status_.rmi_motion_status = 0;
    return fanuc::Reply(PacketKind::kCommunication, name, 0);
  }
  if (name == "FRC_JointMotionJRep") {
    ++motion_commands_;
    const std::optional<fanuc::JointMotion> motion = fanuc::ParseJointMotion(line);
    if (!motion || status_.rmi_motion_status != 1 || status_.servo_ready != 1 || moving_) {
      Say(log, "refused: not initialized, servos off, busy or a malformed instruction");
      return fanuc::Reply(PacketKind::kInstruction, name, 2556943, packet.sequence_id.value_or(0));
    }
    from_ = q_;
    target_ = motion->target_rad;
    const double speed = std::clamp(motion->speed_percent, 1, 100) / 100.0 * kFanucJointSpeedLimit_rad_s;
    move_duration_s_ = (target_ - from_).cwiseAbs().maxCoeff() / speed;
    move_time_s_ = 0;
    moving_ = true;
    sequence_ = motion->sequence_id;
    ++moves_;
    return "";  // answered when the move has run
  }
  return fanuc::Reply(PacketKind::kCommand, "Unknown", 2556929);
}

void FanucFakeController::ServeSession(const Log& log) {
  std::string line;
  while (session_client_.is_open()) {
    const LineIoResult io = session_client_.ReadLine(&line, 0);
    if (io.outcome == LineIo::kTimeout) return;
    if (!io.ok()) {  // the client went away: RMI ends with it unless an instruction still runs
      session_client_.Close();
      if (!moving_) status_.rmi_motion_status = 0;
      return;
    }
    Say(log, "session: " + line);
    Result<fanuc::Packet> packet = fanuc::ParsePacket(line);
    const std::string reply = packet.ok() ? Answer(*packet, line, log) : fanuc::Reply(PacketKind::kCommand, "Unknown", 2556929);
    if (!reply.empty()) Send(reply);
    if (packet.ok() && packet->name == "FRC_Disconnect") session_client_.Close();
  }
}

void FanucFakeController::ResetAtPendant(const Log& log) {
  status_.servo_ready = 1;
  status_.rmi_motion_status = 0;
  Say(log, "pendant: ABORT ALL and RESET: the RMI program ended, the alarm cleared, the servos on");
}

void FanucFakeController::Serve(const std::atomic<bool>& stop, const Log& log, const std::atomic<int>* pendant_resets) {
  MonotonicClock clock;
  double next_s = clock.Now();
  int resets = pendant_resets != nullptr ? pendant_resets->load() : 0;
  while (!stop.load()) {
    if (pendant_resets != nullptr && pendant_resets->load() != resets) {
      resets = pendant_resets->load();
      ResetAtPendant(log);
    }
    ServeClients(log);
    Step(kStep_s, log);
    next_s += kStep_s;
    clock.SleepFor(std::max(0.0, next_s - clock.Now()));
  }
  // What arrived before the stop (an FRC_Abort sent on a fresh session just before the client exited) is
  // counted, as a controller would.
  ServeClients(log);
}

void FanucFakeController::ServeClients(const Log& log) {
  AcceptNewest(&connect_, &connect_client_);
  AcceptNewest(&session_, &session_client_);
  ServeConnect(log);
  ServeSession(log);
}

}  // namespace selfcal::robot
