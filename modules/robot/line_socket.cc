#include "robot/line_socket.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <utility>

#include "robot/clock.h"
#include "robot/robot.h"

namespace selfcal::robot {
namespace {

std::string ErrnoText(int error) { return std::string(std::strerror(error)); }

// Milliseconds left until `deadline_s` for poll(): 0 when past, rounded up otherwise.
int PollMs(double deadline_s) {
  const double left_s = deadline_s - MonotonicClock().Now();
  if (!(left_s > 0)) return 0;
  return static_cast<int>(std::min(std::ceil(left_s * 1e3), 1e9));
}

// poll() for `events` on `fd` until `deadline_s`: > 0 ready, 0 timed out, < 0 error (errno set).
int WaitFor(int fd, short events, double deadline_s) {
  while (true) {
    pollfd entry{fd, events, 0};
    const int ready = ::poll(&entry, 1, PollMs(deadline_s));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0 && MonotonicClock().Now() < deadline_s) continue;  // woke early
    return ready;
  }
}

void SetNoDelay(int fd) {
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
}

bool IsReset(int error) { return error == ECONNRESET || error == EPIPE || error == ENOTCONN; }

}  // namespace

RobotError RobotErrorOfIo(LineIo outcome) {
  return outcome == LineIo::kTimeout ? RobotError::kTimeout : RobotError::kDisconnected;
}

LineSocket::LineSocket(int fd, size_t max_line_bytes) : fd_(fd), max_line_bytes_(max_line_bytes) {
  if (fd_ >= 0) {
    ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
    SetNoDelay(fd_);
  }
}

LineSocket::~LineSocket() { Close(); }

LineSocket::LineSocket(LineSocket&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      max_line_bytes_(other.max_line_bytes_),
      buffer_(std::move(other.buffer_)) {}

LineSocket& LineSocket::operator=(LineSocket&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = std::exchange(other.fd_, -1);
    max_line_bytes_ = other.max_line_bytes_;
    buffer_ = std::move(other.buffer_);
  }
  return *this;
}

void LineSocket::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  buffer_.clear();
}

Result<LineSocket> LineSocket::Connect(const std::string& host, int port, double timeout_s,
                                       size_t max_line_bytes) {
  const std::string where = host + ":" + std::to_string(port);
  const double deadline_s = MonotonicClock().Now() + timeout_s;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* addresses = nullptr;
  const int resolved = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &addresses);
  if (resolved != 0) {
    return RobotFailure(RobotError::kNotConnected, "cannot resolve " + where + ": " + ::gai_strerror(resolved));
  }
  std::string reason = "no address";
  bool timed_out = false;
  for (const addrinfo* address = addresses; address != nullptr; address = address->ai_next) {
    const int fd = ::socket(address->ai_family, address->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC,
                            address->ai_protocol);
    if (fd < 0) {
      reason = "socket: " + ErrnoText(errno);
      continue;
    }
    int error = 0;
    if (::connect(fd, address->ai_addr, address->ai_addrlen) != 0) {
      error = errno;
      if (error == EINPROGRESS) {
        const int ready = WaitFor(fd, POLLOUT, deadline_s);
        if (ready == 0) {
          timed_out = true;
          error = ETIMEDOUT;
        } else {
          socklen_t size = sizeof(error);
          if (ready < 0 || ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) != 0) error = errno;
        }
      }
    }
    if (error == 0) {
      ::freeaddrinfo(addresses);
      return LineSocket(fd, max_line_bytes);
    }
    ::close(fd);
    reason = ErrnoText(error);
  }
  ::freeaddrinfo(addresses);
  if (timed_out) {
    return RobotFailure(RobotError::kTimeout, "cannot connect to " + where + " within " +
                                                  std::to_string(timeout_s) + " s");
  }
  return RobotFailure(RobotError::kNotConnected, "cannot connect to " + where + ": " + reason);
}

LineIoResult LineSocket::WriteLine(const std::string& line, double timeout_s) {
  return WriteBytes(line + "\n", timeout_s);
}

LineIoResult LineSocket::WriteBytes(const std::string& data, double timeout_s) {
  if (fd_ < 0) return {LineIo::kClosed, "not connected"};
  const double deadline_s = MonotonicClock().Now() + timeout_s;
  size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<size_t>(n);
      continue;
    }
    const int error = errno;
    if (n < 0 && error == EINTR) continue;
    if (n < 0 && (error == EAGAIN || error == EWOULDBLOCK)) {
      const int ready = WaitFor(fd_, POLLOUT, deadline_s);
      if (ready == 0) return {LineIo::kTimeout, "could not send within the timeout"};
      if (ready < 0) return {LineIo::kFailed, "poll: " + ErrnoText(errno)};
      continue;
    }
    if (IsReset(error)) return {LineIo::kClosed, ErrnoText(error)};
    return {LineIo::kFailed, "send: " + ErrnoText(error)};
  }
  return {};
}

LineIoResult LineSocket::ReadLine(std::string* line, double timeout_s) {
  if (fd_ < 0) return {LineIo::kClosed, "not connected"};
  const double deadline_s = MonotonicClock().Now() + timeout_s;
  while (true) {
    const size_t end = buffer_.find('\n');
    if (end != std::string::npos) {
      if (end > max_line_bytes_) return {LineIo::kTooLong, "a line of " + std::to_string(end) + " bytes"};
      size_t length = end;
      if (length > 0 && buffer_[length - 1] == '\r') --length;
      line->assign(buffer_, 0, length);
      buffer_.erase(0, end + 1);
      return {};
    }
    if (buffer_.size() > max_line_bytes_) {
      return {LineIo::kTooLong, "more than " + std::to_string(max_line_bytes_) + " bytes without a line end"};
    }
    const LineIoResult filled = Fill(deadline_s);
    if (filled.outcome == LineIo::kTimeout) return {LineIo::kTimeout, "no complete line within the timeout"};
    if (!filled.ok()) return filled;
  }
}

LineIoResult LineSocket::Fill(double deadline_s) {
  while (true) {
    const int ready = WaitFor(fd_, POLLIN, deadline_s);
    if (ready == 0) return {LineIo::kTimeout, "nothing within the timeout"};
    if (ready < 0) return {LineIo::kFailed, "poll: " + ErrnoText(errno)};
    char chunk[4096];
    const ssize_t n = ::recv(fd_, chunk, sizeof(chunk), 0);
    if (n == 0) return {LineIo::kClosed, "closed by the peer"};
    if (n < 0) {
      const int error = errno;
      if (error == EINTR || error == EAGAIN || error == EWOULDBLOCK) continue;
      if (IsReset(error)) return {LineIo::kClosed, ErrnoText(error)};
      return {LineIo::kFailed, "recv: " + ErrnoText(error)};
    }
    buffer_.append(chunk, static_cast<size_t>(n));
    return {};
  }
}

LineIoResult LineSocket::ReadBytes(std::string* data, size_t count, double timeout_s) {
  if (fd_ < 0) return {LineIo::kClosed, "not connected"};
  const double deadline_s = MonotonicClock().Now() + timeout_s;
  while (buffer_.size() < count) {
    const LineIoResult filled = Fill(deadline_s);
    if (!filled.ok()) return filled;
  }
  data->assign(buffer_, 0, count);
  buffer_.erase(0, count);
  return {};
}

LineIoResult LineSocket::DiscardInput() {
  if (fd_ < 0) return {LineIo::kClosed, "not connected"};
  const double now_s = MonotonicClock().Now();
  LineIoResult filled;
  while ((filled = Fill(now_s)).ok()) buffer_.clear();
  buffer_.clear();
  return filled.outcome == LineIo::kTimeout ? LineIoResult{} : filled;
}

TcpListener::~TcpListener() { Close(); }

TcpListener::TcpListener(TcpListener&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), port_(other.port_) {}

TcpListener& TcpListener::operator=(TcpListener&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = std::exchange(other.fd_, -1);
    port_ = other.port_;
  }
  return *this;
}

void TcpListener::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Result<TcpListener> TcpListener::Listen(const std::string& address, int port) {
  const std::string where = address + ":" + std::to_string(port);
  sockaddr_in bind_address{};
  bind_address.sin_family = AF_INET;
  bind_address.sin_port = htons(static_cast<uint16_t>(port));
  if (port < 0 || port > 65535 || ::inet_pton(AF_INET, address.c_str(), &bind_address.sin_addr) != 1) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot listen on " + where + ": not an IPv4 address and port");
  }
  TcpListener listener;
  listener.fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listener.fd_ < 0) return Status::Error(ErrorCode::kInvalidInput, "socket: " + ErrnoText(errno));
  const int one = 1;
  ::setsockopt(listener.fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(listener.fd_, reinterpret_cast<const sockaddr*>(&bind_address), sizeof(bind_address)) != 0 ||
      ::listen(listener.fd_, 4) != 0) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot listen on " + where + ": " + ErrnoText(errno));
  }
  sockaddr_in bound{};
  socklen_t size = sizeof(bound);
  ::getsockname(listener.fd_, reinterpret_cast<sockaddr*>(&bound), &size);
  listener.port_ = ntohs(bound.sin_port);
  return listener;
}

std::optional<LineSocket> TcpListener::Accept(double timeout_s, size_t max_line_bytes) {
  if (fd_ < 0) return std::nullopt;
  if (WaitFor(fd_, POLLIN, MonotonicClock().Now() + timeout_s) <= 0) return std::nullopt;
  const int client = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (client < 0) return std::nullopt;
  return LineSocket(client, max_line_bytes);
}

}  // namespace selfcal::robot
