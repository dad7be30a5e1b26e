// Internal to capture: checksums of recorded files. Atomic writes and capped reads are base/atomic_file.h.
#pragma once

#include <cstdint>
#include <string>

namespace selfcal::capture::internal {

// CRC-32 (IEEE 802.3, the one of zlib and PNG) of `bytes`.
uint32_t Crc32(const std::string& bytes);

std::string Crc32Hex(uint32_t crc);  // 8 lower-case hex digits

}  // namespace selfcal::capture::internal
