// A loopback fake of a Universal Robots controller for the UR backend's tests and rehearsals
// (`selfcal-ur-fake`, docs/universal-robots.md): the RTDE server (protocol version, output recipe setup,
// start, data packages), the secondary interface (robot state messages with the kinematics info at 10 Hz;
// movej and stopj lines) and the Dashboard server, each on 127.0.0.1 only, written from the same
// documents as ur_protocol.h and speaking its byte formats. The arm moves each joint linearly to a movej
// target, all arriving together, the leading joint at movej's v. Faults on request: the connections
// dropped during a move, a protective stop during a move, a move that stops short and never finishes,
// a wrong answer to the recipe setup, remote control off. A protective stop stays until the Dashboard's
// `unlock protective stop` (what a person does at the pendant; selfcal never sends it). It counts the motion commands (movej) it
// received, and every line it receives is passed to `log`. It serves the newest client of each port (a new
// connection replaces the one before); not a real controller.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "base/status.h"
#include "robot/line_socket.h"
#include "robot/ur_protocol.h"

namespace selfcal::robot {

// UR5e's nominal DH values (Universal Robots' published DH table) with checksums 0x1001..0x1006: what a
// fresh controller's kinematics info looks like.
ur::KinematicsInfo Ur5eNominalKinematics();

struct UrFakeOptions {
  int rtde_port = 0;  // 0: an ephemeral port (ports() says which)
  int secondary_port = 0;
  int dashboard_port = 0;
  std::string model = "UR5e";
  std::string serial = "20235500001";
  Eigen::Matrix<double, 6, 1> start_rad = (Eigen::Matrix<double, 6, 1>() << 0, -1.5708, 1.5708, -1.5708, -1.5708, 0).finished();
  ur::KinematicsInfo kinematics = Ur5eNominalKinematics();
  // Faults (0-based move counts; -1: never).
  int drop_move = -1;             // all connections closed half way through this move
  int protective_stop_move = -1;  // a protective stop half way through this move
  int stall_move = -1;            // the arm stops half way and never arrives
  bool wrong_recipe = false;      // the recipe setup answered with NOT_FOUND for safety_status_bits
  bool remote_control_off = false;
  bool protective_stop_at_start = false;
  bool program_running = false;   // runtime_state "playing": someone's program runs on the controller
};

class UrFakeController {
 public:
  // Listens on 127.0.0.1 (the three ports); kInvalidInput when a port is busy.
  static Result<UrFakeController> Listen(const UrFakeOptions& options);

  struct Ports {
    int rtde = 0, secondary = 0, dashboard = 0;
  };
  Ports ports() const { return {rtde_.port(), secondary_.port(), dashboard_.port()}; }

  // Serves until `stop` is set, in steps of 8 ms (the RTDE stream at 125 Hz). `log` gets every received
  // line and what the fake does (may be empty).
  void Serve(const std::atomic<bool>& stop, const std::function<void(const std::string&)>& log);

  // Read after Serve() returned.
  int motion_commands() const { return motion_commands_; }
  int stop_commands() const { return stop_commands_; }

 private:
  explicit UrFakeController(const UrFakeOptions& options);
  void Step(double dt_s, const std::function<void(const std::string&)>& log);
  // Takes new clients and answers what every client sent.
  void ServeClients(const std::function<void(const std::string&)>& log);
  void ServeRtde(const std::function<void(const std::string&)>& log);
  void ServeSecondary(const std::function<void(const std::string&)>& log);
  void ServeDashboard(const std::function<void(const std::string&)>& log);
  void DropAll(const std::function<void(const std::string&)>& log);

  UrFakeOptions options_;
  TcpListener rtde_, secondary_, dashboard_;
  LineSocket rtde_client_, secondary_client_, dashboard_client_;
  bool streaming_ = false;
  ur::UrState state_;
  Eigen::Matrix<double, 6, 1> from_, target_;
  double velocity_ = 0, move_duration_s_ = 0, move_time_s_ = 0;
  bool moving_ = false;
  int moves_ = 0;
  double since_robot_state_s_ = 1;
  int motion_commands_ = 0;
  int stop_commands_ = 0;
};

}  // namespace selfcal::robot
