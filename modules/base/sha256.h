// SHA-256 (FIPS 180-4, through OpenSSL's libcrypto, which stays private to base): the one digest selfcal
// uses for provenance (reports, calibrated models) and for the inputs of a session (session.json).
#pragma once

#include <string>
#include <string_view>

#include "base/status.h"

namespace selfcal {

// SHA-256 of `bytes` as 64 lower-case hex digits.
std::string Sha256Hex(std::string_view bytes);

// SHA-256 of the contents of the regular file `path` (read in chunks, no size cap), 64 lower-case hex
// digits. ErrorCode::kInvalidInput naming the path when it cannot be opened or read, or is not a regular file
// (a directory, FIFO or device is refused without blocking).
Result<std::string> Sha256OfFile(const std::string& path);

}  // namespace selfcal
