// Lines over TCP with timeouts: the transport under the robot line protocol (network_robot.h is the
// client, robot_server.h the server, docs/robot-protocol.md the protocol). Sockets are non-blocking and
// every wait is a poll() with a deadline, so no call blocks longer than its timeout; a line longer than
// the cap is refused instead of buffered without end. Nagle is off (TCP_NODELAY): one short request, one
// short reply. Not thread-safe.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "base/status.h"
#include "robot/robot.h"

namespace selfcal::robot {

enum class LineIo {
  kOk,
  kTimeout,  // nothing (complete) within the timeout
  kClosed,   // the peer closed or reset the connection
  kTooLong,  // a line longer than the cap: the stream cannot be trusted any more
  kFailed,   // another socket error (see the message)
};

// The robot failure a failed exchange is: kTimeout for kTimeout, kDisconnected for every other outcome.
RobotError RobotErrorOfIo(LineIo outcome);

struct LineIoResult {
  LineIo outcome = LineIo::kOk;
  std::string error;  // errno text or what was wrong; empty on kOk
  bool ok() const { return outcome == LineIo::kOk; }
};

class LineSocket {
 public:
  LineSocket() = default;
  // Takes ownership of a connected socket `fd` and makes it non-blocking.
  LineSocket(int fd, size_t max_line_bytes);
  ~LineSocket();
  LineSocket(LineSocket&& other) noexcept;
  LineSocket& operator=(LineSocket&& other) noexcept;
  LineSocket(const LineSocket&) = delete;
  LineSocket& operator=(const LineSocket&) = delete;

  // A TCP connection to host:port (a name or a numeric IPv4/IPv6 address) within `timeout_s`. Errors are
  // robot failures: kTimeout when the attempt did not finish in time, kNotConnected otherwise (refused,
  // unknown host, ...), naming host:port and the reason.
  static Result<LineSocket> Connect(const std::string& host, int port, double timeout_s, size_t max_line_bytes);

  bool is_open() const { return fd_ >= 0; }
  void Close();

  // Sends `line` followed by "\n" (the line must not contain one) within `timeout_s`.
  LineIoResult WriteLine(const std::string& line, double timeout_s);
  // The next line without its "\n" (and without a "\r" before it), waiting at most `timeout_s` (0: only
  // what has already arrived). A partial line stays buffered for the next call.
  LineIoResult ReadLine(std::string* line, double timeout_s);
  // Bytes received beyond the lines read so far.
  bool has_buffered_input() const { return !buffer_.empty(); }

  // Binary use (the UR backend's RTDE and primary interfaces, ur_protocol.h): sends `data` as it is.
  LineIoResult WriteBytes(const std::string& data, double timeout_s);
  // Exactly `count` bytes, waiting at most `timeout_s` (0: only what has already arrived); on a timeout
  // the bytes received so far stay buffered for the next call.
  LineIoResult ReadBytes(std::string* data, size_t count, double timeout_s);
  // Reads and drops whatever has arrived (a stream nobody reads must not fill the socket); kClosed when
  // the peer closed or reset the connection.
  LineIoResult DiscardInput();

 private:
  // One poll() until `deadline_s` and one recv() into the buffer.
  LineIoResult Fill(double deadline_s);

  int fd_ = -1;
  size_t max_line_bytes_ = 0;
  std::string buffer_;
};

// A listening TCP socket on one address (e.g. 127.0.0.1) for the server.
class TcpListener {
 public:
  TcpListener() = default;
  ~TcpListener();
  TcpListener(TcpListener&& other) noexcept;
  TcpListener& operator=(TcpListener&& other) noexcept;
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;

  // Binds `address`:`port` (numeric IPv4; port 0: an ephemeral port) with SO_REUSEADDR and listens.
  // Errors: ErrorCode::kInvalidInput naming the address and errno (a busy port is the user's to change).
  static Result<TcpListener> Listen(const std::string& address, int port);

  bool is_open() const { return fd_ >= 0; }
  int port() const { return port_; }
  // A client that connected within `timeout_s` (0: only one already waiting), or nullopt.
  std::optional<LineSocket> Accept(double timeout_s, size_t max_line_bytes);
  void Close();

 private:
  int fd_ = -1;
  int port_ = 0;
};

}  // namespace selfcal::robot
