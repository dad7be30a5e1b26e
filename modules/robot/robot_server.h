// The robot server: serves any `Robot` over the selfcal line protocol (docs/robot-protocol.md), one client
// at a time. selfcal-robot-sim runs it in front of the simulated robot; the tests run it on a thread
// against NetworkRobot; it is also the reference for anyone writing a server beside a real controller.
//
// Behaviour beyond the request/reply table of the protocol:
//   - HELLO calls robot.Connect() (so a client's reconnect also reconnects the robot), then Identity() and
//     Limits(); requests other than HELLO and BYE before it get `ERR bad_request`;
//   - a Robot call that fails with kDisconnected is not answered: the server closes the client's socket,
//     which is how the simulated robot's lost connection (R10) reaches the client;
//   - whenever the connection of a client that said HELLO ends (BYE, EOF, a socket error, a line over
//     the cap, the drop hook below, the server stopping) the server calls robot.Stop(): the arm never
//     moves unattended;
//   - a second client while one is served gets `ERR fault busy ...` and is closed.
#pragma once

#include <atomic>
#include <cstddef>
#include <iosfwd>
#include <set>
#include <string>

#include "base/status.h"
#include "robot/line_protocol.h"
#include "robot/line_socket.h"
#include "robot/robot.h"

namespace selfcal::robot {

struct RobotServerOptions {
  std::string address = "127.0.0.1";  // numeric IPv4 to bind
  int port = 0;                       // 0: an ephemeral port (see RobotServer::port())
  double poll_interval_s = 0.05;      // how often Serve() looks at its stop flag
  size_t max_line_bytes = protocol::kMaxLineBytes;
  // Test hook (R10): after replying OK to MOVE request #k (0-based, counted over the server's life), close
  // the client's connection, as a cable pulled mid-move would.
  std::set<int> drop_client_after_moves;
  std::ostream* log = nullptr;  // connection events and refusals, one line each; nullptr: silent
};

class RobotServer {
 public:
  // `robot` must outlive the server and must not be used by anyone else while Serve() runs.
  RobotServer(Robot& robot, RobotServerOptions options = {});

  // Binds and listens. Errors: ErrorCode::kInvalidInput naming the address (e.g. the port is in use).
  Status Listen();
  // The bound port (after Listen()).
  int port() const { return listener_.port(); }

  // Serves clients one at a time until `stop` becomes true (looked at every poll_interval_s); then closes
  // the client and the listening socket. Requires Listen().
  Status Serve(const std::atomic<bool>& stop);

  int moves_served() const { return moves_served_; }

 private:
  // Handles one request line; sets *close_client when the connection must end after the reply (if any).
  // Returns the reply, or "" for no reply (lost robot connection).
  std::string Handle(const std::string& line, bool* close_client);
  // The ERR reply for a failed Robot call, or "" (and *close_client) when the robot's link is gone.
  std::string Failure(const Status& status, bool* close_client);
  void EndClient(LineSocket& client, const std::string& why);
  void Log(const std::string& line);

  Robot& robot_;
  RobotServerOptions options_;
  TcpListener listener_;
  bool hello_done_ = false;
  int moves_served_ = 0;
};

}  // namespace selfcal::robot
