#include "rosbag/mcap_reader.h"

#include <cstring>

#include <zstd.h>

#include "base/atomic_file.h"
#include "base/crc32.h"

namespace selfcal::rosbag {

namespace {

constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::uint8_t kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05,
                       kChunk = 0x06;
constexpr std::uint64_t kRecordPrefix = 9;  // opcode u8 + length u64

// A bounds-checked little-endian reader over one record's content.
class Fields {
 public:
  Fields(const char* data, std::uint64_t size) : data_(data), size_(size) {}

  template <typename T>
  bool Int(T* value) {
    if (size_ - pos_ < sizeof(T)) return false;
    T v = 0;
    for (size_t k = 0; k < sizeof(T); ++k) {
      v = static_cast<T>(v | (static_cast<T>(static_cast<unsigned char>(data_[pos_ + k])) << (8 * k)));
    }
    pos_ += sizeof(T);
    *value = v;
    return true;
  }
  // `count` bytes.
  bool Bytes(std::uint64_t count, std::string* out) {
    if (size_ - pos_ < count) return false;
    out->assign(data_ + pos_, count);
    pos_ += count;
    return true;
  }
  bool String(std::string* out) {
    std::uint32_t n = 0;
    return Int(&n) && Bytes(n, out);
  }
  bool Skip32() {
    std::uint32_t n = 0;
    if (!Int(&n) || size_ - pos_ < n) return false;
    pos_ += n;
    return true;
  }
  std::uint64_t pos() const { return pos_; }
  std::uint64_t left() const { return size_ - pos_; }
  const char* here() const { return data_ + pos_; }

 private:
  const char* data_;
  std::uint64_t size_;
  std::uint64_t pos_ = 0;
};

struct Scan {
  const std::string& path;
  const std::set<std::string>& topics;
  const McapLimits& limits;
  McapContents contents;
  std::map<std::uint16_t, std::pair<std::string, std::string>> schemas;  // id -> name, encoding
  std::uint64_t kept_bytes = 0;
};

// Where a record lies: the file's byte offset, or a chunk's and the offset in its records.
std::string Where(const std::string& path, std::uint64_t chunk_offset, bool in_chunk, std::uint64_t offset) {
  if (!in_chunk) return path + ": byte " + std::to_string(offset);
  return path + ": chunk at byte " + std::to_string(chunk_offset) + ", byte " + std::to_string(offset) +
         " of its uncompressed records";
}

Status Bad(const std::string& where, const std::string& what) {
  return Status::Error(ErrorCode::kInvalidInput, where + ": " + what + " (not a readable MCAP file)");
}

Status ReadSchema(Scan* scan, Fields f, const std::string& where) {
  std::uint16_t id = 0;
  std::string name, encoding;
  if (!f.Int(&id) || !f.String(&name) || !f.String(&encoding) || !f.Skip32()) {
    return Bad(where, "Schema record shorter than its fields");
  }
  if (id != 0) scan->schemas.emplace(id, std::make_pair(name, encoding));  // id 0 is invalid: ignored
  return Status::Ok();
}

Status ReadChannel(Scan* scan, Fields f, const std::string& where) {
  McapChannel c;
  std::uint16_t schema_id = 0;
  if (!f.Int(&c.id) || !f.Int(&schema_id) || !f.String(&c.topic) || !f.String(&c.message_encoding) || !f.Skip32()) {
    return Bad(where, "Channel record shorter than its fields");
  }
  if (schema_id != 0) {
    auto schema = scan->schemas.find(schema_id);
    if (schema == scan->schemas.end()) {
      return Bad(where, "channel " + std::to_string(c.id) + " (" + c.topic + ") names schema " +
                            std::to_string(schema_id) + ", which no earlier Schema record defines");
    }
    c.schema_name = schema->second.first;
    c.schema_encoding = schema->second.second;
  }
  scan->contents.channels.emplace(c.id, c);  // a repeated channel (summary section) is the same one
  return Status::Ok();
}

Status ReadMessage(Scan* scan, Fields f, const std::string& where) {
  McapMessage m;
  std::uint32_t sequence = 0;
  std::uint64_t publish_time = 0;
  if (!f.Int(&m.channel_id) || !f.Int(&sequence) || !f.Int(&m.log_time_ns) || !f.Int(&publish_time)) {
    return Bad(where, "Message record shorter than its 22-byte fields");
  }
  auto channel = scan->contents.channels.find(m.channel_id);
  if (channel == scan->contents.channels.end()) {
    return Bad(where, "message on channel " + std::to_string(m.channel_id) + ", which no earlier Channel record defines");
  }
  if (scan->topics.count(channel->second.topic) == 0) return Status::Ok();
  scan->kept_bytes += f.left();
  if (scan->kept_bytes > scan->limits.max_kept_bytes) {
    return Bad(where, "the messages of the requested topics exceed " + std::to_string(scan->limits.max_kept_bytes >> 20) +
                          " MiB");
  }
  f.Bytes(f.left(), &m.data);
  m.where = where;
  scan->contents.messages.push_back(std::move(m));
  return Status::Ok();
}

Status ScanRecords(Scan* scan, const char* data, std::uint64_t size, std::uint64_t base, bool in_chunk,
                   std::uint64_t chunk_offset, std::uint64_t* footer_at);

// A Chunk: its records decompressed (checked against the stated size and CRC) and scanned.
Status ReadChunk(Scan* scan, Fields f, const std::string& where, std::uint64_t record_offset) {
  std::uint64_t start = 0, end = 0, uncompressed_size = 0, records_size = 0;
  std::uint32_t crc = 0;
  std::string compression;
  if (!f.Int(&start) || !f.Int(&end) || !f.Int(&uncompressed_size) || !f.Int(&crc) || !f.String(&compression) ||
      !f.Int(&records_size) || f.left() < records_size) {
    return Bad(where, "Chunk record shorter than its fields");
  }
  if (uncompressed_size > scan->limits.max_chunk_bytes) {
    return Bad(where, "chunk of " + std::to_string(uncompressed_size) + " uncompressed bytes, more than the " +
                          std::to_string(scan->limits.max_chunk_bytes >> 20) + " MiB read");
  }
  std::string records;
  if (compression.empty()) {
    if (records_size != uncompressed_size) {
      return Bad(where, "uncompressed chunk of " + std::to_string(records_size) + " bytes states " +
                            std::to_string(uncompressed_size));
    }
    records.assign(f.here(), records_size);
  } else if (compression == "zstd") {
    records.resize(uncompressed_size);
    const size_t got = ZSTD_decompress(records.data(), records.size(), f.here(), records_size);
    if (ZSTD_isError(got)) return Bad(where, std::string("zstd chunk does not decompress: ") + ZSTD_getErrorName(got));
    if (got != uncompressed_size) {
      return Bad(where, "zstd chunk decompresses to " + std::to_string(got) + " bytes, states " +
                            std::to_string(uncompressed_size));
    }
  } else if (compression == "lz4") {
    return Status::Error(ErrorCode::kInvalidInput,
                         where + ": lz4-compressed chunk: this build reads uncompressed and zstd chunks only; "
                                 "convert the bag, e.g. `mcap compress --compression zstd` or `ros2 bag convert`");
  } else {
    return Bad(where, "chunk compression `" + compression + "` is not one MCAP defines (\"\", zstd, lz4)");
  }
  if (crc != 0 && Crc32(records) != crc) {
    return Bad(where, "chunk records fail their CRC-32 (stated " + Crc32Hex(crc) + ", computed " +
                          Crc32Hex(Crc32(records)) + ")");
  }
  return ScanRecords(scan, records.data(), records.size(), 0, true, record_offset, nullptr);
}

// The records of data[0, size) (base: the file offset of data[0] at the top level); stops at the Footer
// (its offset in *footer_at) at the top level.
Status ScanRecords(Scan* scan, const char* data, std::uint64_t size, std::uint64_t base, bool in_chunk,
                   std::uint64_t chunk_offset, std::uint64_t* footer_at) {
  std::uint64_t pos = 0;
  bool first = true;
  while (pos < size) {
    const std::string where = Where(scan->path, chunk_offset, in_chunk, base + pos);
    if (size - pos < kRecordPrefix) {
      return Bad(where, "the " + std::to_string(size - pos) + " bytes left cannot hold a record's opcode and length");
    }
    Fields prefix(data + pos, kRecordPrefix);
    std::uint8_t op = 0;
    std::uint64_t length = 0;
    prefix.Int(&op);
    prefix.Int(&length);
    if (length > size - pos - kRecordPrefix) {
      return Bad(where, "record (opcode 0x" + Crc32Hex(op).substr(6) + ") of " + std::to_string(length) +
                            " bytes runs past the end (" + std::to_string(size - pos - kRecordPrefix) + " bytes left)");
    }
    Fields content(data + pos + kRecordPrefix, length);
    if (!in_chunk && first && op != kHeader) return Bad(where, "the first record is not a Header");
    first = false;
    Status s = Status::Ok();
    if (op == kSchema) {
      s = ReadSchema(scan, content, where);
    } else if (op == kChannel) {
      s = ReadChannel(scan, content, where);
    } else if (op == kMessage) {
      s = ReadMessage(scan, content, where);
    } else if (op == kChunk) {
      if (in_chunk) return Bad(where, "a Chunk inside a chunk");
      s = ReadChunk(scan, content, where, base + pos);
    } else if (op == kFooter) {
      if (in_chunk) return Bad(where, "a Footer inside a chunk");
      if (length != 20) return Bad(where, "Footer of " + std::to_string(length) + " bytes, not 20");
      *footer_at = base + pos;
      return Status::Ok();
    }  // every other record (indexes, attachments, metadata, statistics, data end, unknown) is skipped
    if (!s.ok()) return s;
    pos += kRecordPrefix + length;
  }
  if (in_chunk) return Status::Ok();
  return Bad(Where(scan->path, 0, false, base + size), "the file ends without a Footer record (a recording cut short?)");
}

}  // namespace

Result<McapContents> ParseMcap(const std::string& bytes, const std::string& path, const std::set<std::string>& topics,
                               const McapLimits& limits) {
  constexpr std::uint64_t kMagicSize = sizeof(kMagic);
  if (bytes.size() < kMagicSize || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0) {
    return Bad(path + ": byte 0", "the file does not start with the MCAP magic 89 4D 43 41 50 30 0D 0A");
  }
  Scan scan{path, topics, limits, {}, {}, 0};
  std::uint64_t footer_at = 0;
  if (Status s = ScanRecords(&scan, bytes.data() + kMagicSize, bytes.size() - kMagicSize, kMagicSize, false, 0, &footer_at);
      !s.ok()) {
    return s;
  }
  const std::uint64_t end = footer_at + kRecordPrefix + 20;
  if (bytes.size() - end != kMagicSize || std::memcmp(bytes.data() + end, kMagic, kMagicSize) != 0) {
    return Bad(path + ": byte " + std::to_string(end), "the Footer is not followed by the closing MCAP magic and the end of the file");
  }
  return scan.contents;
}

Result<McapContents> ReadMcap(const std::string& path, const std::set<std::string>& topics, const McapLimits& limits) {
  Result<std::string> bytes = ReadFileCapped(path, limits.max_file_bytes);
  if (!bytes.ok()) return bytes.status();
  return ParseMcap(*bytes, path, topics, limits);
}

}  // namespace selfcal::rosbag
