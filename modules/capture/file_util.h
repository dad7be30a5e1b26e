// Internal to capture: file helpers for recorded sequences.
//
// capture (layer 2) may not use io (layer 5), whose atomic_file.h does the same for the calibration
// core; these follow the same rules (temporary file in the target directory, fsync, rename or link,
// fsync of the directory; size-capped reads that refuse non-regular files without blocking).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "base/status.h"

namespace selfcal::capture::internal {

enum class Publish {
  kReplace,    // rename over `path` (an index rewritten in place)
  kNoReplace,  // link to `path`, refusing an existing file (recorded images are never overwritten)
};

// Writes `contents` to ".<name>.tmp.XXXXXX" beside `path`, fsyncs it, publishes it as `path` and fsyncs
// the directory. On failure `path` is untouched and the temporary file removed. ExitCode::kUsage
// naming `path` and the system error.
Status WriteFileAtomically(const std::string& path, const std::string& contents, Publish publish);

// A whole regular file of at most `max_bytes` (size checked with fstat before reading). ExitCode::kUsage
// naming `path`; `missing` (optional) is set when the file does not exist.
Result<std::string> ReadFileCapped(const std::string& path, std::size_t max_bytes, bool* missing = nullptr);

// CRC-32 (IEEE 802.3, the one of zlib and PNG) of `bytes`.
uint32_t Crc32(const std::string& bytes);

std::string Crc32Hex(uint32_t crc);  // 8 lower-case hex digits

}  // namespace selfcal::capture::internal
