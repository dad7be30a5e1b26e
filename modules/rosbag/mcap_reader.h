// A reader of MCAP files (https://mcap.dev/spec, the format rosbag2 records in by default since ROS 2 Iron),
// written from the published specification: the magic, then records `<opcode u8><length u64><content>`
// (integers little-endian, strings and byte arrays length-prefixed), the Header first and the Footer last,
// followed by the magic again. The messages are found by scanning every record in file order (the summary
// section and the indexes are not needed and not used): Schema, Channel and Message records at the top level
// or inside Chunk records, whose records are uncompressed (compression "") or zstd-compressed (libzstd);
// lz4 chunks are refused by name. Every length is checked against what holds it before it is used; a
// damaged or truncated file is refused with the file and the byte offset of the record (and inside a chunk
// the offset in its uncompressed records), never read past.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::rosbag {

struct McapChannel {
  std::uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr" for ROS 2
  std::string schema_name;       // e.g. "sensor_msgs/msg/JointState"; empty without a schema
  std::string schema_encoding;   // e.g. "ros2msg"
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint64_t log_time_ns = 0;
  std::string where;  // "FILE: byte N" (or "FILE: chunk at byte M, byte N"), for messages about its content
  std::string data;   // the serialized message
};

struct McapContents {
  std::map<std::uint16_t, McapChannel> channels;  // every channel of the file
  std::vector<McapMessage> messages;              // the messages of the requested topics, in file order
};

struct McapLimits {
  std::uint64_t max_file_bytes = std::uint64_t{64} << 30;      // 64 GiB
  std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;      // a chunk's uncompressed records
  std::uint64_t max_kept_bytes = std::uint64_t{8} << 30;       // the kept messages' data in all
};

// The file's channels and the messages on `topics`. ErrorCode::kInvalidInput naming the file and byte
// offset for a missing or wrong magic, a record or field that runs past what holds it, a message on an
// unknown channel, a chunk that does not decompress to its stated size or fails its CRC, a compression
// other than "" and "zstd", a missing footer; limits exceeded are refused the same way.
Result<McapContents> ReadMcap(const std::string& path, const std::set<std::string>& topics,
                              const McapLimits& limits = {});

// The same on a file's bytes already in memory (`path` names it in messages): the tests' entry point.
Result<McapContents> ParseMcap(const std::string& bytes, const std::string& path, const std::set<std::string>& topics,
                               const McapLimits& limits = {});

}  // namespace selfcal::rosbag
