// File access shared by every module that writes or reads files (io for the calibration core, capture for
// recorded sequences): atomic publication (P4) - a reader sees either the old file or the complete new one,
// never a truncated mix, even after a crash or power loss - and size-capped reading (C8).
#pragma once

#include <cstddef>
#include <string>

#include "base/status.h"

namespace selfcal {

// Status::detail_domain() of the failures below that come from a system call: Status::detail() is its errno
// (e.g. ENOSPC), so that a caller can tell a full or failing disk (a hardware fault during a session, P5)
// from a bad path (a configuration error).
inline constexpr const char* kErrnoDomain = "errno";

enum class Publish {
  kReplace,    // rename over `path` (a file rewritten in place: configs, results, a sequence index)
  kNoReplace,  // link to `path`, refusing an existing file (recorded images are never overwritten)
};

// Writes `contents` to a temporary file in the directory of `path` (".<name>.tmp.XXXXXX"), fsyncs it,
// publishes it as `path` and fsyncs the directory. Permissions of a new file are 0644. On failure the
// temporary file is removed, `path` is untouched, and the Status (ErrorCode::kInvalidInput: the output location
// is part of the configuration, C10) names the path and the system error (also as the kErrnoDomain detail).
Status WriteFileAtomically(const std::string& path, const std::string& contents, Publish publish = Publish::kReplace);

// Reads a whole regular file of at most `max_bytes`; the size is checked (fstat) before reading, and
// reading stops one byte past the cap should the file grow meanwhile. FIFOs, devices and directories
// are refused without blocking. ErrorCode::kInvalidInput, naming the path (with the kErrnoDomain detail when a
// system call failed); `missing` (optional) is set when the file does not exist.
Result<std::string> ReadFileCapped(const std::string& path, std::size_t max_bytes, bool* missing = nullptr);

// Low-level pieces of the above for modules that keep a file open and append to it (the session journal).
// Each retries on EINTR and returns false with errno set on failure.
bool WriteAllToFd(int fd, const std::string& bytes);  // write() until every byte is written
bool FsyncRetrying(int fd);
bool FsyncDirectory(const std::string& directory);  // open(O_DIRECTORY) + fsync + close

}  // namespace selfcal
