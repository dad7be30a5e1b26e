#include "session/session_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <sstream>
#include <utility>

#include "base/atomic_file.h"
#include "session/file_util.h"

namespace selfcal::session {

namespace {

using internal::SystemError;

std::string Trimmed(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

// The lock file's contents (at most 4 KiB: it holds one short line).
std::string ReadHolder(int fd) {
  char buffer[4096];
  ssize_t n;
  do {
    n = ::pread(fd, buffer, sizeof(buffer), 0);
  } while (n < 0 && errno == EINTR);
  return n > 0 ? Trimmed(std::string(buffer, static_cast<std::size_t>(n))) : "";
}

std::string HostName() {
  char host[256] = {};
  if (::gethostname(host, sizeof(host) - 1) != 0 || host[0] == '\0') return "unknown-host";
  return host;
}

// "pid N on host H (since T)" from a holder line, or the line itself when it does not parse.
std::string DescribeHolder(const std::string& line) {
  std::istringstream in(line);
  std::string pid, host, since;
  if (!(in >> pid >> host)) return line.empty() ? "another process (its lock line is not written yet)" : line;
  in >> since;
  return "pid " + pid + " on host " + host + (since.empty() ? "" : " (since " + since + ")");
}

}  // namespace

std::string LockHolderNamed(const std::string& session_path) {
  const std::string path = internal::Join(session_path, kLockFileName);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return "";
  const std::string line = ReadHolder(fd);
  ::close(fd);
  return line.empty() ? "" : DescribeHolder(line);
}

std::string UtcNowIso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

Result<SessionLock> SessionLock::Acquire(const std::string& session_path, bool must_create, bool take_over_stale) {
  const std::string path = internal::Join(session_path, kLockFileName);
  SessionLock lock;
  const int flags = O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | (must_create ? O_EXCL : 0);
  lock.fd_ = ::open(path.c_str(), flags, 0644);
  if (lock.fd_ < 0) {
    if (must_create && errno == EEXIST) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "session " + session_path + " is being created by another process (its lock file exists)");
    }
    return SystemError("cannot open the lock file", path, errno);
  }
  int rc;
  do {
    rc = ::flock(lock.fd_, LOCK_EX | LOCK_NB);
  } while (rc != 0 && errno == EINTR);
  if (rc != 0) {
    const int error = errno;
    if (error == EWOULDBLOCK) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "session " + session_path + " is in use by " + DescribeHolder(ReadHolder(lock.fd_)));
    }
    return SystemError("cannot lock", path, error);
  }
  lock.stale_from_ = ReadHolder(lock.fd_);
  if (!lock.stale_from_.empty() && !take_over_stale) {  // P6: the operator confirms; the line stays (held_ false)
    return Status::Error(ErrorCode::kInvalidInput,
                         "session " + session_path + ": its lock was left by " + DescribeHolder(lock.stale_from_) +
                             ", which no longer holds it (it ended without releasing it). If no selfcal on that host "
                             "uses this session, take the lock over with --take-over-stale-lock");
  }
  lock.held_ = true;
  const std::string line = std::to_string(::getpid()) + " " + HostName() + " " + UtcNowIso8601() + "\n";
  if (::ftruncate(lock.fd_, 0) != 0) return SystemError("cannot write the lock file", path, errno);
  if (!WriteAllToFd(lock.fd_, line)) return SystemError("cannot write the lock file", path, errno);
  if (!FsyncRetrying(lock.fd_)) return SystemError("cannot fsync the lock file", path, errno);
  return lock;
}

SessionLock::SessionLock(SessionLock&& other) noexcept { *this = std::move(other); }

SessionLock& SessionLock::operator=(SessionLock&& other) noexcept {
  if (this != &other) {
    Release();
    fd_ = std::exchange(other.fd_, -1);
    held_ = std::exchange(other.held_, false);
    stale_from_ = std::move(other.stale_from_);
  }
  return *this;
}

SessionLock::~SessionLock() { Release(); }

void SessionLock::Release() {
  if (fd_ < 0) return;
  // Emptied while still locked: an empty lock file means "released cleanly", a non-empty unlocked one
  // "its holder died". Best effort: a failure only makes the next holder report a stale lock.
  // Only the holder empties it: a refused Acquire must not blank the line of the process that holds it.
  if (held_ && ::ftruncate(fd_, 0) == 0) FsyncRetrying(fd_);
  ::close(fd_);
  fd_ = -1;
  held_ = false;
}

}  // namespace selfcal::session
