// Test-only builders of MCAP records and CDR messages, for the unit tests of this module (the independent
// writer of the integration test is test/tools/mcap_writer, npm's @mcap/core and @foxglove/cdr).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace selfcal::rosbag::testing {

template <typename T>
void Put(std::string* out, T value) {
  for (size_t k = 0; k < sizeof(T); ++k) out->push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * k)) & 0xff));
}
inline void PutString(std::string* out, const std::string& s) {
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(s.size()));
  *out += s;
}
inline std::string Record(std::uint8_t op, const std::string& content) {
  std::string r(1, static_cast<char>(op));
  Put<std::uint64_t>(&r, content.size());
  return r + content;
}
inline std::string Magic() { return std::string("\x89MCAP0\r\n", 8); }
inline std::string HeaderRecord() {
  std::string c;
  PutString(&c, "ros2");
  PutString(&c, "test");
  return Record(0x01, c);
}
inline std::string SchemaRecord(std::uint16_t id, const std::string& name) {
  std::string c;
  Put<std::uint16_t>(&c, id);
  PutString(&c, name);
  PutString(&c, "ros2msg");
  PutString(&c, "");
  return Record(0x03, c);
}
inline std::string ChannelRecord(std::uint16_t id, std::uint16_t schema, const std::string& topic) {
  std::string c;
  Put<std::uint16_t>(&c, id);
  Put<std::uint16_t>(&c, schema);
  PutString(&c, topic);
  PutString(&c, "cdr");
  Put<std::uint32_t>(&c, 0);
  return Record(0x04, c);
}
inline std::string MessageRecord(std::uint16_t channel, std::uint64_t time_ns, const std::string& data) {
  std::string c;
  Put<std::uint16_t>(&c, channel);
  Put<std::uint32_t>(&c, 0);
  Put<std::uint64_t>(&c, time_ns);
  Put<std::uint64_t>(&c, time_ns);
  return Record(0x05, c + data);
}
inline std::string ChunkRecord(const std::string& compression, const std::string& records, const std::string& stored,
                               std::uint32_t crc) {
  std::string c;
  Put<std::uint64_t>(&c, 0);
  Put<std::uint64_t>(&c, 0);
  Put<std::uint64_t>(&c, records.size());
  Put<std::uint32_t>(&c, crc);
  PutString(&c, compression);
  Put<std::uint64_t>(&c, stored.size());
  return Record(0x06, c + stored);
}
inline std::string FooterRecord() { return Record(0x02, std::string(20, '\0')); }

// CDR little-endian with alignment counted after the 4-byte encapsulation header.
class CdrWriter {
 public:
  CdrWriter() : bytes_(std::string("\x00\x01\x00\x00", 4)) {}
  template <typename T>
  CdrWriter& Add(T value) {
    while ((bytes_.size() - 4) % (sizeof(T) < 8 ? sizeof(T) : 8) != 0) bytes_.push_back('\0');
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes_.append(raw, sizeof(T));
    return *this;
  }
  CdrWriter& Str(const std::string& s) {
    Add<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    bytes_ += s;
    bytes_.push_back('\0');
    return *this;
  }
  CdrWriter& Doubles(const std::vector<double>& v) {
    Add<std::uint32_t>(static_cast<std::uint32_t>(v.size()));
    for (double d : v) Add(d);
    return *this;
  }
  CdrWriter& Octets(const std::string& v) {
    Add<std::uint32_t>(static_cast<std::uint32_t>(v.size()));
    bytes_ += v;
    return *this;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

inline std::string JointStateCdr(std::int32_t sec, std::uint32_t nsec, const std::vector<std::string>& names,
                                 const std::vector<double>& position) {
  CdrWriter w;
  w.Add(sec).Add(nsec).Str("base").Add<std::uint32_t>(static_cast<std::uint32_t>(names.size()));
  for (const std::string& n : names) w.Str(n);
  w.Doubles(position).Doubles({}).Doubles({});
  return w.bytes();
}

}  // namespace selfcal::rosbag::testing
