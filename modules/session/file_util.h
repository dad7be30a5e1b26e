// Internal to session: the error vocabulary of its file system calls (which errno is a hardware fault,
// which a configuration error) and the file-name rules of a session directory.
#pragma once

#include <string>

#include "base/status.h"

namespace selfcal::session::internal {

// kHardware for a full or failing disk (ENOSPC, EDQUOT, EIO), kInvalidInput for everything else (a missing,
// read-only or foreign path is part of the configuration, C10).
ErrorCode ErrorCodeForErrno(int error);

// "<what> <path>: <strerror(error)>" with the code of ErrorCodeForErrno.
Status SystemError(const std::string& what, const std::string& path, int error);

// A Status from base/atomic_file.h whose code is re-derived from its errno detail (a WriteFileAtomically
// that ran out of space becomes kHardware); other statuses unchanged.
Status WithErrnoErrorCode(const Status& status);

// A plain file name: 1-255 printable ASCII characters, no '/' or '\', not hidden (no leading '.').
bool SafeFileName(const std::string& name);

// `directory` + "/" + `name`.
std::string Join(const std::string& directory, const std::string& name);

}  // namespace selfcal::session::internal
