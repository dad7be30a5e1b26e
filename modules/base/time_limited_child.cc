#include "base/time_limited_child.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace selfcal {

namespace {

// In the child: writes all of `bytes`, then ends without running exit handlers or flushing stdio.
[[noreturn]] void WriteAndExit(int fd, const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) ::_exit(2);
    done += static_cast<size_t>(n);
  }
  ::_exit(0);
}

[[noreturn]] void RunChild(int fd, const std::function<std::string()>& work) {
  std::string bytes;
  try {
    bytes = work();
  } catch (...) {
    ::_exit(3);
  }
  WriteAndExit(fd, bytes);
}

ChildOutput Failed(const std::string& detail, ChildEnd end = ChildEnd::kFailed) {
  ChildOutput out;
  out.end = end;
  out.detail = detail;
  return out;
}

// How the child ended, once its pipe is closed.
ChildOutput Reap(pid_t pid, std::string bytes) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return Failed(std::string("waitpid: ") + std::strerror(errno));
  }
  if (WIFSIGNALED(status)) return Failed("ended by signal " + std::to_string(WTERMSIG(status)), ChildEnd::kCrashed);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3) return Failed("the work threw an exception", ChildEnd::kCrashed);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return Failed("exited with status " + std::to_string(WEXITSTATUS(status)));
  }
  ChildOutput out;
  out.end = ChildEnd::kFinished;
  out.bytes = std::move(bytes);
  return out;
}

}  // namespace

ChildOutput RunInTimeLimitedChild(const std::function<std::string()>& work, std::chrono::milliseconds limit) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return Failed(std::string("pipe: ") + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    return Failed(std::string("fork: ") + std::strerror(error));
  }
  if (pid == 0) {
    ::close(fds[0]);
    RunChild(fds[1], work);
  }
  ::close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + limit;
  std::string bytes;
  char buffer[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fds[0], POLLIN, 0};
    const int ready = left.count() > 0 ? ::poll(&p, 1, static_cast<int>(left.count())) : 0;
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) {  // the limit passed, or poll failed: the child is stopped, whatever it was doing
      const int error = errno;
      ::kill(pid, SIGKILL);
      ::close(fds[0]);
      int status = 0;
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      if (ready < 0) return Failed(std::string("poll: ") + std::strerror(error));
      ChildOutput out;
      out.end = ChildEnd::kTimedOut;
      return out;
    }
    const ssize_t n = ::read(fds[0], buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of file: the child has written everything (or failed; Reap says which)
    bytes.append(buffer, static_cast<size_t>(n));
  }
  ::close(fds[0]);
  return Reap(pid, std::move(bytes));
}

}  // namespace selfcal
