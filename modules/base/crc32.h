// CRC-32 of recorded files and journal records (capture's sequence index, session's journal framing).
#pragma once

#include <cstdint>
#include <string>

namespace selfcal {

// CRC-32/ISO-HDLC (IEEE 802.3; the one of zlib, PNG and gzip) of `bytes`: zlib's crc32.
std::uint32_t Crc32(const std::string& bytes);

std::string Crc32Hex(std::uint32_t crc);  // 8 lower-case hex digits

}  // namespace selfcal
