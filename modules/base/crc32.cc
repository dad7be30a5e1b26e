#include "base/crc32.h"

#include <cstdio>

#include <zlib.h>

namespace selfcal {

std::uint32_t Crc32(const std::string& bytes) {
  // crc32_z takes a size_t length (crc32 only a 32-bit one).
  const auto* data = reinterpret_cast<const Bytef*>(bytes.data());
  return static_cast<std::uint32_t>(crc32_z(crc32_z(0L, Z_NULL, 0), data, bytes.size()));
}

std::string Crc32Hex(std::uint32_t crc) {
  char hex[9];
  std::snprintf(hex, sizeof(hex), "%08x", crc);
  return hex;
}

}  // namespace selfcal
