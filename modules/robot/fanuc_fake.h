// A loopback fake of a FANUC controller's Remote Motion Interface for the FANUC backend's tests and
// rehearsals (`selfcal-fanuc-fake`, docs/fanuc.md): the connect port (FRC_Connect names the session port)
// and the session port (FRC_Initialize, FRC_GetStatus, FRC_ReadJointAngles, FRC_JointMotionJRep answered
// when the move has run, FRC_Abort, FRC_Reset, FRC_Disconnect), each on 127.0.0.1 only, written from the
// same documents as fanuc_protocol.h and speaking its packets. The arm moves each joint linearly to a
// target, all arriving together, the leading joint at Speed % of kFanucJointSpeedLimit_rad_s. Faults on
// request: the connection dropped during a move, the servos switched off during a move (FRC_SystemFault,
// ServoReady 0, the instruction answered with an error), a move that stops short and never finishes, a
// wrong answer to FRC_ReadJointAngles during a move, the servos off or the teach pendant enabled at start.
// It counts the motion instructions and the aborts it received; every packet it receives is passed to
// `log`. It serves the newest client of each port; not a real controller.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "base/status.h"
#include "robot/fanuc_protocol.h"
#include "robot/line_socket.h"

namespace selfcal::robot {

struct FanucFakeOptions {
  int connect_port = 0;  // 0: an ephemeral port (connect_port() says which)
  Eigen::Matrix<double, 6, 1> start_rad = (Eigen::Matrix<double, 6, 1>() << 0, 0, 0, 0, -1.5708, 0).finished();
  // Faults (0-based move counts; -1: never).
  int drop_move = -1;       // the session connection closed half way through this move
  int servo_off_move = -1;  // the servos off half way through this move (an alarm)
  int stall_move = -1;      // the arm stops half way and never arrives
  int wrong_answer_move = -1;  // half way through this move FRC_ReadJointAngles is answered as another command
  bool servo_off_at_start = false;
  bool teach_pendant_enabled = false;
  bool silent_abort = false;  // FRC_Abort stops the arm but is never answered (an answer lost on the way)
};

class FanucFakeController {
 public:
  // Listens on 127.0.0.1 (the connect port and an ephemeral session port); kInvalidInput when busy.
  static Result<FanucFakeController> Listen(const FanucFakeOptions& options);

  int connect_port() const { return connect_.port(); }
  int session_port() const { return session_.port(); }

  // Serves until `stop` is set, in steps of 8 ms. `log` gets every received packet and what the fake does.
  // Each increase of *pendant_resets is a person pressing RESET at the teach pendant (ResetAtPendant).
  void Serve(const std::atomic<bool>& stop, const std::function<void(const std::string&)>& log,
             const std::atomic<int>* pendant_resets = nullptr);

  // ABORT ALL and RESET at the pendant: the RMI program ended (RMIMotionStatus 0: a client must initialise
  // it again), an alarm cleared, the servos on again (ServoReady 1). Nothing moves.
  void ResetAtPendant(const std::function<void(const std::string&)>& log);

  // Read after Serve() returned.
  int motion_commands() const { return motion_commands_; }
  int stop_commands() const { return stop_commands_; }

 private:
  explicit FanucFakeController(const FanucFakeOptions& options);
  void Step(double dt_s, const std::function<void(const std::string&)>& log);
  // Takes new clients and answers what every client sent.
  void ServeClients(const std::function<void(const std::string&)>& log);
  void ServeConnect(const std::function<void(const std::string&)>& log);
  void ServeSession(const std::function<void(const std::string&)>& log);
  std::string Answer(const fanuc::Packet& packet, const std::string& line, const std::function<void(const std::string&)>& log);
  void Send(const std::string& packet);

  FanucFakeOptions options_;
  TcpListener connect_, session_;
  LineSocket connect_client_, session_client_;
  fanuc::ControllerStatus status_;
  Eigen::Matrix<double, 6, 1> q_, from_, target_;
  double move_duration_s_ = 0, move_time_s_ = 0;
  bool moving_ = false;
  bool wrong_answer_now_ = false;
  int moves_ = 0;
  int sequence_ = 0;
  int time_tag_ = 0;
  int motion_commands_ = 0;
  int stop_commands_ = 0;
};

}  // namespace selfcal::robot
