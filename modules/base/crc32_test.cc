#include "base/crc32.h"

#include <string>

#include <gtest/gtest.h>

namespace selfcal {
namespace {

// Reference values of CRC-32/ISO-HDLC; the journal payload is framed in every existing session the same
// way, so these also pin that existing journals and sequence indexes stay readable.
TEST(Crc32, StandardCheckValues) {
  EXPECT_EQ(Crc32(""), 0x00000000u);
  EXPECT_EQ(Crc32("a"), 0xe8b7be43u);
  EXPECT_EQ(Crc32("123456789"), 0xcbf43926u);  // the catalogue's check value
  EXPECT_EQ(Crc32("The quick brown fox jumps over the lazy dog"), 0x414fa339u);
  EXPECT_EQ(Crc32("{\"type\":\"plan\",\"poses\":3}"), 0x17e575eau);
  std::string all_bytes;
  for (int i = 0; i < 256; ++i) all_bytes.push_back(static_cast<char>(i));
  EXPECT_EQ(Crc32(all_bytes), 0x29058c73u);
}

TEST(Crc32, HexIsEightLowerCaseDigits) {
  EXPECT_EQ(Crc32Hex(0xcbf43926u), "cbf43926");
  EXPECT_EQ(Crc32Hex(0x0000abcdu), "0000abcd");
  EXPECT_EQ(Crc32Hex(0xFFFFFFFFu), "ffffffff");
}

}  // namespace
}  // namespace selfcal
