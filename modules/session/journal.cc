#include "session/journal.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <utility>

#include "base/atomic_file.h"
#include "base/crc32.h"
#include "base/json_lines.h"
#include "session/file_util.h"

namespace selfcal::session {

namespace {

using internal::SystemError;

// "J1 " + 8 hex + " " + 8 hex + " ".
constexpr std::size_t kHeaderBytes = 21;

enum class Parsed {
  kValid,
  kIncomplete,  // a prefix of a record: the file ends inside it
  kInvalid,     // framing, length, CRC or terminator wrong
  kBadPayload,  // framing and CRC right, payload not a JSON object with a "type" string
  kCarriageReturn,  // a carriage return where the record's newline belongs: line ends converted
};

struct ParseResult {
  Parsed kind = Parsed::kInvalid;
  std::size_t end = 0;  // one past the newline (kValid, kBadPayload)
  std::string reason;
  nlohmann::json payload;
};

bool IsLowerHex(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); }

// Whether `c` may stand at position `i` of a record header.
bool HeaderCharOk(std::size_t i, char c) {
  static constexpr char kFixed[] = "J1 ";
  if (i < 3) return c == kFixed[i];
  if (i == 11 || i == 20) return c == ' ';
  return IsLowerHex(c);
}

std::uint32_t HexValue(const std::string& data, std::size_t pos) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 8; ++i) {
    const char c = data[pos + i];
    value = value * 16 + static_cast<std::uint32_t>(c <= '9' ? c - '0' : c - 'a' + 10);
  }
  return value;
}

// Parses a payload with a nesting-depth cap; false with `why` set when it is not a JSON object with a
// "type" string.
bool ParsePayload(const std::string& text, int max_depth, nlohmann::json* out, std::string* why) {
  bool too_deep = false;
  const nlohmann::json::parser_callback_t depth_guard = [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > max_depth) too_deep = true;
    return !too_deep;
  };
  nlohmann::json value = nlohmann::json::parse(text, depth_guard, /*allow_exceptions=*/false);
  if (too_deep) {
    *why = "payload nested deeper than " + std::to_string(max_depth);
    return false;
  }
  if (value.is_discarded()) {
    *why = "payload is not valid JSON";
    return false;
  }
  if (!value.is_object()) {
    *why = "payload is not a JSON object";
    return false;
  }
  if (const std::optional<JsonDuplicateKey> duplicate = FindDuplicateJsonKey(text)) {
    *why = "payload gives `" + JsonPointerName(duplicate->pointer) + "` twice";
    return false;
  }
  const auto type = value.find("type");
  if (type == value.end() || !type->is_string()) {
    *why = "payload has no \"type\" string";
    return false;
  }
  *out = std::move(value);
  return true;
}

ParseResult ParseRecordAt(const std::string& data, std::size_t pos, const JournalLimits& limits) {
  ParseResult result;
  const std::size_t available = data.size() - pos;
  for (std::size_t i = 0; i < kHeaderBytes && i < available; ++i) {
    if (!HeaderCharOk(i, data[pos + i])) {
      result.reason = "bad record header (byte " + std::to_string(i) + " of the header)";
      return result;
    }
  }
  if (available < kHeaderBytes) {
    result.kind = Parsed::kIncomplete;
    result.reason =
        "incomplete record header (" + std::to_string(available) + " of " + std::to_string(kHeaderBytes) + " bytes)";
    return result;
  }
  const std::uint32_t length = HexValue(data, pos + 3);
  const std::uint32_t crc = HexValue(data, pos + 12);
  if (length > limits.max_record_bytes) {
    result.reason = "record length " + std::to_string(length) + " exceeds the limit of " +
                    std::to_string(limits.max_record_bytes) + " bytes";
    return result;
  }
  const std::size_t total = kHeaderBytes + length + 1;
  if (available < total) {
    result.kind = Parsed::kIncomplete;
    result.reason = "incomplete record (" + std::to_string(available) + " of " + std::to_string(total) + " bytes)";
    return result;
  }
  if (data[pos + total - 1] != '\n') {
    result.reason = "no newline at the end of the record";
    if (data[pos + total - 1] == '\r') result.kind = Parsed::kCarriageReturn;
    return result;
  }
  const std::string payload = data.substr(pos + kHeaderBytes, length);
  const std::uint32_t actual = Crc32(payload);
  if (actual != crc) {
    result.reason = "CRC mismatch (recorded " + Crc32Hex(crc) + ", computed " + Crc32Hex(actual) + ")";
    return result;
  }
  result.end = pos + total;
  result.kind = ParsePayload(payload, limits.max_json_depth, &result.payload, &result.reason) ? Parsed::kValid
                                                                                              : Parsed::kBadPayload;
  return result;
}

// The offset of the first record after `pos` whose framing and CRC are right (a record a writer
// completed), or npos.
std::size_t FindLaterRecord(const std::string& data, std::size_t pos, const JournalLimits& limits) {
  for (std::size_t at = data.find("J1 ", pos + 1); at != std::string::npos; at = data.find("J1 ", at + 1)) {
    const Parsed kind = ParseRecordAt(data, at, limits).kind;
    if (kind == Parsed::kValid || kind == Parsed::kBadPayload) return at;
  }
  return std::string::npos;
}

std::string RecordName(std::size_t index, std::size_t offset) {
  return "record " + std::to_string(index + 1) + " at byte offset " + std::to_string(offset);
}

Result<std::string> ReadAll(int fd, const std::string& path, std::uint64_t max_bytes) {
  struct stat info {};
  if (::fstat(fd, &info) != 0) return SystemError("cannot stat journal", path, errno);
  if (!S_ISREG(info.st_mode)) return Status::Error(ErrorCode::kInvalidInput, "journal " + path + " is not a regular file");
  if (static_cast<std::uint64_t>(info.st_size) > max_bytes) {
    return Status::Error(ErrorCode::kInvalidInput, "journal " + path + " is " + std::to_string(info.st_size) +
                                               " bytes, more than the limit of " + std::to_string(max_bytes) + " bytes");
  }
  std::string data(static_cast<std::size_t>(info.st_size), '\0');
  std::size_t used = 0;
  while (used < data.size()) {
    const ssize_t n = ::pread(fd, data.data() + used, data.size() - used, static_cast<off_t>(used));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return SystemError("cannot read journal", path, errno);
    if (n == 0) break;
    used += static_cast<std::size_t>(n);
  }
  data.resize(used);
  return data;
}

std::string DirectoryOf(const std::string& path) {
  const std::string parent = std::filesystem::path(path).parent_path().string();
  return parent.empty() ? "." : parent;
}

// Lines of `data` from `pos` on that hold anything but NUL bytes (a crash on some file systems leaves a tail
// of zeros).
int NonEmptyLines(const std::string& data, std::size_t pos) {
  int lines = 0;
  bool content = false;
  for (std::size_t k = pos; k < data.size(); ++k) {
    if (data[k] == '\n') {
      lines += content ? 1 : 0;
      content = false;
    } else if (data[k] != '\0') {
      content = true;
    }
  }
  return lines + (content ? 1 : 0);
}

// Parses the whole journal `data` into *records. A torn tail is only reported in *recovery (valid_bytes:
// where it starts, dropped_bytes: its length); damage and faulty writers are refused (kInvalidInput).
Status ParseJournal(const std::string& data, const std::string& path, const JournalLimits& limits,
                    std::vector<nlohmann::json>* records, JournalRecovery* recovery) {
  std::size_t pos = 0;
  while (pos < data.size()) {
    ParseResult record = ParseRecordAt(data, pos, limits);
    if (record.kind == Parsed::kValid) {
      records->push_back(std::move(record.payload));
      pos = record.end;
      continue;
    }
    const std::string where = "journal " + path + ": " + RecordName(records->size(), pos);
    if (record.kind == Parsed::kBadPayload) {
      return Status::Error(ErrorCode::kInvalidInput, where + " has a correct CRC but a bad payload (" + record.reason +
                                                 "): written by a faulty writer, not torn by a crash; refusing it");
    }
    if (record.kind == Parsed::kCarriageReturn) {  // a crash never writes one there: CRLF or CR line ends
      return Status::Error(ErrorCode::kInvalidInput,
                           where + " ends with a carriage return where its newline belongs: the journal's line ends "
                                   "were converted (CRLF or CR: an editor, git's autocrlf); it is damaged, refusing "
                                   "it (nothing was changed)");
    }
    const std::size_t later = FindLaterRecord(data, pos, limits);
    if (later != std::string::npos) {
      return Status::Error(ErrorCode::kInvalidInput, where + " is corrupt (" + record.reason +
                                                 ") and a valid record follows it at byte offset " +
                                                 std::to_string(later) +
                                                 ": the journal is damaged, not torn by a crash; refusing to drop "
                                                 "records (nothing was changed)");
    }
    if (data.find("\rJ1 ", pos) != std::string::npos) {  // a crash never writes one there: CR line ends
      return Status::Error(ErrorCode::kInvalidInput,
                           where + " is corrupt (" + record.reason + ") and records separated by a carriage return "
                                   "follow it: the journal's line ends were converted (CR: an editor); it is "
                                   "damaged, refusing it (nothing was changed)");
    }
    // One interrupted append leaves one line at most (a prefix of a record, or a record whose bytes did not
    // all reach the disk); several lines of text after the last valid record are not a tail torn by a
    // crash but a damaged or replaced journal, which a resume would otherwise cut to its valid part.
    if (const int lines = NonEmptyLines(data, pos); lines > 1) {
      return Status::Error(ErrorCode::kInvalidInput, where + " is corrupt (" + record.reason + ") and " +
                                                 std::to_string(lines) +
                                                 " lines follow the last valid record: the journal is damaged or "
                                                 "replaced, not torn by a crash; refusing to drop them (nothing was "
                                                 "changed)");
    }
    recovery->dropped_bytes = data.size() - pos;
    recovery->reason = record.reason + ": " + RecordName(records->size(), pos);
    break;
  }
  recovery->valid_bytes = pos;
  return Status::Ok();
}

}  // namespace

std::string FrameJournalRecord(const std::string& payload) {
  char header[kHeaderBytes + 1];
  std::snprintf(header, sizeof(header), "J1 %08x %s ", static_cast<unsigned>(payload.size()),
                Crc32Hex(Crc32(payload)).c_str());
  return std::string(header) + payload + "\n";
}

Result<Journal> Journal::Open(const std::string& path, const JournalLimits& limits) {
  Journal journal;
  journal.path_ = path;
  journal.limits_ = limits;
  journal.fd_ = ::open(path.c_str(), O_RDWR | O_APPEND | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (journal.fd_ >= 0) {
    journal.recovery_.created = true;
    if (!FsyncDirectory(DirectoryOf(path))) return SystemError("cannot fsync the directory of journal", path, errno);
  } else if (errno == EEXIST) {
    journal.fd_ = ::open(path.c_str(), O_RDWR | O_APPEND | O_CLOEXEC | O_NOFOLLOW);
  }
  if (journal.fd_ < 0) return SystemError("cannot open journal", path, errno);

  Result<std::string> read = ReadAll(journal.fd_, path, limits.max_file_bytes);
  if (!read.ok()) return read.status();
  if (Status s = ParseJournal(*read, path, limits, &journal.records_, &journal.recovery_); !s.ok()) return s;
  const std::uint64_t pos = journal.recovery_.valid_bytes;
  if (journal.recovery_.truncated()) {
    // A torn tail: cut it off so that the next Append starts on a record boundary.
    if (::ftruncate(journal.fd_, static_cast<off_t>(pos)) != 0) {
      return SystemError("cannot truncate the torn tail of journal", path, errno);
    }
    if (!FsyncRetrying(journal.fd_)) return SystemError("cannot fsync journal", path, errno);
  }
  journal.size_bytes_ = pos;
  return journal;
}

Result<JournalContents> ReadJournal(const std::string& path, const JournalLimits& limits) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return SystemError("cannot open journal", path, errno);
  Result<std::string> read = ReadAll(fd, path, limits.max_file_bytes);
  ::close(fd);
  if (!read.ok()) return read.status();
  JournalContents contents;
  if (Status s = ParseJournal(*read, path, limits, &contents.records, &contents.recovery); !s.ok()) return s;
  return contents;
}

Journal::Journal(Journal&& other) noexcept { *this = std::move(other); }

Journal& Journal::operator=(Journal&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    limits_ = other.limits_;
    records_ = std::move(other.records_);
    recovery_ = std::move(other.recovery_);
    size_bytes_ = other.size_bytes_;
    failure_ = std::move(other.failure_);
  }
  return *this;
}

Journal::~Journal() { Close(); }

void Journal::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status Journal::Append(const nlohmann::json& record) {
  SELFCAL_CHECK(record.is_object() && record.contains("type") && record["type"].is_string(),
                "a journal record is a JSON object with a \"type\" string, got " << record.dump());
  SELFCAL_CHECK(fd_ >= 0, "Append on a moved-from journal");
  if (!failure_.empty()) {
    return Status::Error(ErrorCode::kHardware, "journal " + path_ + " is unusable after an earlier error (" + failure_ +
                                                  "); reopen the session to recover it");
  }
  const std::string payload = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (payload.size() > limits_.max_record_bytes) {
    return Status::Error(ErrorCode::kInvalidInput, "journal " + path_ + ": a " + record["type"].get<std::string>() +
                                               " record of " + std::to_string(payload.size()) +
                                               " bytes exceeds the limit of " +
                                               std::to_string(limits_.max_record_bytes) + " bytes");
  }
  // Parsed back before writing: a record Open would refuse (too deep) is never written.
  nlohmann::json stored;
  std::string why;
  if (!ParsePayload(payload, limits_.max_json_depth, &stored, &why)) {
    return Status::Error(ErrorCode::kInvalidInput, "journal " + path_ + ": cannot append a " +
                                               record["type"].get<std::string>() + " record: " + why);
  }
  const std::string line = FrameJournalRecord(payload);
  if (size_bytes_ + line.size() > limits_.max_file_bytes) {
    return Status::Error(ErrorCode::kInvalidInput, "journal " + path_ + " would exceed its limit of " +
                                               std::to_string(limits_.max_file_bytes) + " bytes");
  }
  const bool written = WriteAllToFd(fd_, line);
  const bool durable = written && ::fdatasync(fd_) == 0;
  if (!durable) {
    const int error = errno;
    // Cut off what reached the file so that the journal stays a sequence of whole records; should that
    // fail too, Open will drop the torn line as a torn tail.
    const bool restored = ::ftruncate(fd_, static_cast<off_t>(size_bytes_)) == 0;
    const Status status = SystemError(written ? "cannot fdatasync journal" : "cannot append to journal", path_, error);
    failure_ = status.message() + (restored ? "" : "; the partial record could not be cut off");
    return status;
  }
  size_bytes_ += line.size();
  records_.push_back(std::move(stored));
  return Status::Ok();
}

}  // namespace selfcal::session
