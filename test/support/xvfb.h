// An Xvfb server for the tests that draw in an X window (the live view): started on a display number
// it chooses itself (-displayfd), stopped by its pid at destruction. Tests skip when Xvfb is absent
// (Debian: xvfb, in scripts/install-deps).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include <visp3/core/vpColor.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>

namespace selfcal::testing {

// Sets $DISPLAY (or unsets it, for an empty `display`) for its lifetime; restores it at destruction.
class ScopedDisplay {
 public:
  explicit ScopedDisplay(const std::string& display) {
    if (const char* d = std::getenv("DISPLAY")) saved_ = d, had_ = true;
    display.empty() ? ::unsetenv("DISPLAY") : ::setenv("DISPLAY", display.c_str(), 1);
  }
  ~ScopedDisplay() { had_ ? ::setenv("DISPLAY", saved_.c_str(), 1) : ::unsetenv("DISPLAY"); }
  ScopedDisplay(const ScopedDisplay&) = delete;
  ScopedDisplay& operator=(const ScopedDisplay&) = delete;

 private:
  std::string saved_;
  bool had_ = false;
};

// Whether a pixel within `radius` px of (u, v) has exactly `color` (an overlay drawn by vpDisplay).
inline bool ColorNear(const vpImage<vpRGBa>& image, double u, double v, const vpColor& color, int radius = 2) {
  for (int dv = -radius; dv <= radius; ++dv) {
    for (int du = -radius; du <= radius; ++du) {
      const int r = static_cast<int>(std::lround(v)) + dv, c = static_cast<int>(std::lround(u)) + du;
      if (r < 0 || c < 0 || r >= static_cast<int>(image.getHeight()) || c >= static_cast<int>(image.getWidth())) {
        continue;
      }
      const vpRGBa& p = image[r][c];
      if (p.R == color.R && p.G == color.G && p.B == color.B) return true;
    }
  }
  return false;
}

class XvfbServer {
 public:
  XvfbServer() = default;
  ~XvfbServer() { Stop(); }
  // Stops the server (its clients lose their connection).
  void Stop() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    if (lock_fd_ >= 0) {
      ::close(lock_fd_);  // releases the flock
      lock_fd_ = -1;
    }
  }
  XvfbServer(const XvfbServer&) = delete;
  XvfbServer& operator=(const XvfbServer&) = delete;

  static std::string Binary() {
    for (const char* path : {"/usr/bin/Xvfb", "/usr/local/bin/Xvfb"}) {
      if (::access(path, X_OK) == 0) return path;
    }
    return "";
  }

  // Starts Xvfb with one 24-bit screen; true once it accepts connections (its display in display()),
  // else false with *why.
  bool Start(std::string* why) {
    const std::string binary = Binary();
    if (binary.empty()) {
      *why = "Xvfb is not installed (Debian: apt-get install xvfb, or scripts/install-deps)";
      return false;
    }
    // -noreset: without it the server resets when its last client leaves, and a connection opened during
    // the reset fails (a probe that opens and closes the display, then the view, saw that under load).
    // One test server at a time on this machine: Xvfb servers started at the same moment (ctest -j) race
    // for display numbers, and one of them then reports a display its clients cannot open.
    lock_fd_ = ::open("/tmp/selfcal-test-xvfb.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX) != 0) {
      *why = "cannot take /tmp/selfcal-test-xvfb.lock";
      return false;
    }
    int fds[2];
    if (::pipe(fds) != 0) {
      *why = "pipe failed";
      return false;
    }
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], 3);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      ::execl(binary.c_str(), "Xvfb", "-displayfd", "3", "-screen", "0", "1280x1024x24", "-nolisten", "tcp", "-noreset",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    while (::poll(&p, 1, 15000) > 0) {  // Xvfb writes "<n>\n" once it is ready
      char c = 0;
      if (::read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    ::close(fds[0]);
    if (number.empty()) {
      *why = "Xvfb did not report a display within 15 s";
      return false;
    }
    display_ = ":" + number;
    return true;
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  int lock_fd_ = -1;
  std::string display_;
};

}  // namespace selfcal::testing
