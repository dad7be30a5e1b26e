// The MCAP reader on files built record by record (test_bytes.h): topics kept, chunks uncompressed and
// zstd, and refusals that name the byte; then every truncation and seeded byte flips of a valid file,
// each read without a crash and refused with the file's name (or read, for a flip in a payload).
#include "rosbag/mcap_reader.h"

#include <random>

#include <gtest/gtest.h>
#include <zstd.h>

#include "base/crc32.h"
#include "rosbag/test_bytes.h"

namespace selfcal::rosbag {
namespace {

using namespace testing;  // NOLINT: the builders

std::string Records() {
  return SchemaRecord(1, "sensor_msgs/msg/JointState") + ChannelRecord(1, 1, "/joint_states") +
         SchemaRecord(2, "std_msgs/msg/String") + ChannelRecord(2, 2, "/chatter");
}

std::string File(const std::string& data) { return Magic() + HeaderRecord() + data + FooterRecord() + Magic(); }

std::string Zstd(const std::string& bytes) {
  std::string out(ZSTD_compressBound(bytes.size()), '\0');
  out.resize(ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), 3));
  return out;
}

// A file with a message at the top level, one in an uncompressed chunk and one in a zstd chunk.
std::string ValidFile() {
  const std::string in_plain = MessageRecord(1, 2000, "second") + MessageRecord(2, 2100, "chatter");
  const std::string in_zstd = MessageRecord(1, 3000, "third");
  return File(Records() + MessageRecord(1, 1000, "first") + ChunkRecord("", in_plain, in_plain, Crc32(in_plain)) +
              ChunkRecord("zstd", in_zstd, Zstd(in_zstd), Crc32(in_zstd)) + Record(0x0f, std::string(4, '\0')));
}

TEST(McapReader, KeepsTheRequestedTopicsFromTheTopLevelAndBothKindsOfChunk) {
  Result<McapContents> read = ParseMcap(ValidFile(), "bag.mcap", {"/joint_states"});
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->messages.size(), 3u);
  EXPECT_EQ(read->messages[0].data, "first");
  EXPECT_EQ(read->messages[1].data, "second");
  EXPECT_EQ(read->messages[2].data, "third");
  EXPECT_EQ(read->messages[2].log_time_ns, 3000u);
  EXPECT_NE(read->messages[1].where.find("chunk at byte"), std::string::npos) << read->messages[1].where;
  EXPECT_EQ(read->channels.at(1).schema_name, "sensor_msgs/msg/JointState");
  EXPECT_EQ(read->channels.at(2).topic, "/chatter");
}

void ExpectRefused(const std::string& bytes, const std::string& words) {
  Result<McapContents> read = ParseMcap(bytes, "bag.mcap", {"/joint_states"});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(read.status().message().find(words), std::string::npos) << read.status().message();
  EXPECT_EQ(read.status().message().rfind("bag.mcap: ", 0), 0u) << read.status().message();
}

TEST(McapReader, RefusesWhatTheSpecificationDoesNotAllowNamingTheByte) {
  ExpectRefused("not an mcap file", "byte 0: the file does not start with the MCAP magic");
  ExpectRefused(Magic() + Records(), "byte 8: the first record is not a Header");
  ExpectRefused(Magic() + HeaderRecord() + Records(), "ends without a Footer");
  ExpectRefused(File(MessageRecord(7, 1, "x")), "channel 7, which no earlier Channel record defines");
  ExpectRefused(File(Records() + ChunkRecord("lz4", "abc", "abc", 0)), "lz4-compressed chunk");
  ExpectRefused(File(Records() + ChunkRecord("gzip", "abc", "abc", 0)), "compression `gzip`");
  const std::string inner = MessageRecord(1, 5, "x");
  ExpectRefused(File(Records() + ChunkRecord("", inner, inner, Crc32(inner) ^ 1)), "CRC-32");
  ExpectRefused(File(Records() + ChunkRecord("zstd", inner, "garbage", 0)), "zstd chunk does not decompress");
  ExpectRefused(File(Records() + ChunkRecord("", inner, inner.substr(0, 10), 0)), "uncompressed chunk of 10 bytes");
  ExpectRefused(File(Records() + ChunkRecord("", inner + "\x05", inner + "\x05", 0)), "cannot hold a record's opcode");
  ExpectRefused(ValidFile() + "x", "not followed by the closing MCAP magic");
  // A record whose length runs past the file, at its own offset (the Header at byte 8 ends at 8 + 9 + 16).
  std::string long_record = Magic() + HeaderRecord() + Record(0x05, "abc");
  long_record[long_record.size() - 11] = '\x7f';
  ExpectRefused(long_record, "byte 33: record (opcode 0x05) of 127 bytes runs past the end (3 bytes left)");
}

TEST(McapReader, EveryTruncationIsRefusedWithoutACrash) {
  const std::string valid = ValidFile();
  for (size_t n = 0; n < valid.size(); ++n) {
    Result<McapContents> read = ParseMcap(valid.substr(0, n), "cut.mcap", {"/joint_states"});
    ASSERT_FALSE(read.ok()) << "a file cut at byte " << n << " was read";
    EXPECT_EQ(read.status().message().rfind("cut.mcap: byte ", 0), 0u) << read.status().message();
  }
}

TEST(McapReader, SeededByteFlipsAreReadOrRefusedWithoutACrash) {
  const std::string valid = ValidFile();
  std::mt19937 random(38);
  int refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string bytes = valid;
    for (int k = 0; k < 1 + trial % 4; ++k) {
      bytes[random() % bytes.size()] = static_cast<char>(random() & 0xff);
    }
    Result<McapContents> read = ParseMcap(bytes, "flip.mcap", {"/joint_states", "/chatter"});
    if (!read.ok()) {
      ++refused;
      EXPECT_EQ(read.status().message().rfind("flip.mcap: ", 0), 0u) << read.status().message();
    }
  }
  EXPECT_GT(refused, 1000);  // most flips land in lengths, opcodes, magic or CRC-checked chunks
}

TEST(McapReader, AFileMissingOnDiskIsAnInputError) {
  Result<McapContents> read = ReadMcap("/nonexistent/bag.mcap", {"/joint_states"});
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("/nonexistent/bag.mcap"), std::string::npos);
}

}  // namespace
}  // namespace selfcal::rosbag
