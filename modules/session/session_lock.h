// The advisory lock of a session directory (../shared/RELIABILITY.md P6): one process at a time records into or
// resumes a session.
//
// `<session>/lock` is opened (created when absent) and locked with flock(LOCK_EX | LOCK_NB); it then holds
// one line "<pid> <host> <start time, UTC ISO 8601>" naming the holder. flock belongs to the open file
// description, so a second process, and a second SessionLock in the same process, are refused; the kernel
// drops the lock when its holder dies, however it dies. A lock file that still names a holder but is not
// locked was left by a process that died (a clean release empties the file), or by one on another host
// whose file system does not share flock: it is taken over only when the caller says the operator
// confirmed it (`take_over_stale`; `selfcal run --take-over-stale-lock`), and the dead holder's line is
// reported (stale_from) for the log; otherwise it is refused, left as it was. The file itself is never deleted, which keeps
// flock free of the races of unlink-and-recreate.
#pragma once

#include <string>

#include "base/status.h"

namespace selfcal::session {

inline constexpr const char* kLockFileName = "lock";

class SessionLock {
 public:
  // Locks `<session_path>/lock`. With `must_create` the lock file must not exist yet (a new session:
  // two processes creating the same directory cannot both succeed). Errors: kInvalidInput "session <path> is in
  // use by pid N on host H (since T)" when another holder has it; kInvalidInput or kHardware (full disk) naming
  // the file when it cannot be created, locked or written; kInvalidInput "... was left by pid N on host H
  // ... take it over with --take-over-stale-lock" for a stale lock without `take_over_stale`.
  static Result<SessionLock> Acquire(const std::string& session_path, bool must_create = false,
                                     bool take_over_stale = false);

  SessionLock(SessionLock&& other) noexcept;
  SessionLock& operator=(SessionLock&& other) noexcept;
  SessionLock(const SessionLock&) = delete;
  SessionLock& operator=(const SessionLock&) = delete;
  ~SessionLock();  // Release()

  // Empties the lock file and closes it (which drops the flock). Idempotent.
  void Release();

  // The line of a dead holder found in the lock file when it was taken over; empty when the file was new
  // or had been released cleanly.
  const std::string& stale_from() const { return stale_from_; }

 private:
  SessionLock() = default;
  int fd_ = -1;
  bool held_ = false;  // flock succeeded
  std::string stale_from_;
};

// The holder the lock file `<session_path>/lock` names ("pid N on host H (since T)"), read without
// creating, writing or locking it: whether that process still holds it only Acquire can tell. Empty when
// the file is absent or empty (released cleanly). For a dry run's report of what a resume would meet.
std::string LockHolderNamed(const std::string& session_path);

// The current time (CLOCK_REALTIME) as UTC ISO 8601 with seconds, e.g. "2025-03-01T12:00:00Z". Only for
// the lock line and for callers choosing a session's creation time; nothing recorded depends on it.
std::string UtcNowIso8601();

}  // namespace selfcal::session
