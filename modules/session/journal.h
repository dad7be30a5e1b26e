// The append-only journal of a calibration session (../shared/RELIABILITY.md P1, P2; docs/session-format.md): one
// framed, checksummed record per event, durable before it counts, with recovery of a torn tail after a
// crash and refusal of damage anywhere else.
//
// File format: a sequence of lines
//
//   J1 <length: 8 lower-case hex> <CRC-32 of the payload: 8 lower-case hex> <payload>\n
//
// where the payload is `length` bytes of compact single-line JSON (an object with a "type" string).
// JSON escapes control characters inside strings, so a payload never holds a raw newline.
//
// Recovery on Open. Records are read from the start; the first record that is incomplete or invalid (bad
// framing, length over the limit, CRC mismatch, missing newline) ends the valid part. Then:
//  - if no valid record starts at any line after it, what follows the last valid record is a torn tail
//    (a write cut short by a crash or power loss, or the zeros a file system may leave): it is truncated
//    away (ftruncate + fsync) and reported in JournalRecovery;
//  - if a valid record follows, the file was damaged, not torn: Open refuses (ErrorCode::kInvalidInput) naming
//    the byte offset and the record number (counted from 1) of the bad record, and changes nothing;
//  - a complete record whose CRC matches but whose payload is not a JSON object with a "type" string was
//    written by a faulty writer, not torn by a crash: refused in the same way, even at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/status.h"

namespace selfcal::session {

inline constexpr const char* kJournalFileName = "journal.log";

struct JournalLimits {
  std::size_t max_record_bytes = std::size_t{1} << 20;    // payload of one record: 1 MiB
  std::uint64_t max_file_bytes = std::uint64_t{1} << 30;  // the whole journal: 1 GiB
  int max_json_depth = 64;                                // nesting depth of a payload
};

// What Open found and did (ReadJournal: what Open would do; nothing is dropped there).
struct JournalRecovery {
  std::uint64_t valid_bytes = 0;    // length of the valid records, kept; the byte offset of a torn tail
  std::uint64_t dropped_bytes = 0;  // length of the torn tail truncated away (0: nothing dropped)
  std::string reason;               // why the tail was dropped, e.g. "incomplete record (41 of 97 bytes)"
  bool created = false;             // the file did not exist and was created empty
  bool truncated() const { return dropped_bytes > 0; }
};

class Journal {
 public:
  // Opens `path` for appending, creating it (0644, with a directory fsync) when absent; reads and
  // validates every record and truncates a torn tail as described above. Errors: kInvalidInput for a file that
  // is damaged, not a regular file, over the limits or not accessible; kHardware for an I/O error
  // (read, ftruncate or fsync failing).
  static Result<Journal> Open(const std::string& path, const JournalLimits& limits = JournalLimits());

  Journal(Journal&& other) noexcept;
  Journal& operator=(Journal&& other) noexcept;
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  ~Journal();

  // Appends `record` (a JSON object with a "type" string: SELFCAL_CHECK) as one framed line, with one
  // write() loop followed by fdatasync(): when this returns OK the record is durable (P1). Invalid UTF-8
  // in strings is replaced by U+FFFD. Errors: kInvalidInput for a record over max_record_bytes or a journal that
  // would exceed max_file_bytes (nothing written); kHardware naming the file for an I/O error (ENOSPC,
  // EIO, ...). After an I/O error the partial line is cut off again when possible, the record does not
  // count, and every later Append fails: reopen the session (Open recovers the journal).
  Status Append(const nlohmann::json& record);

  // The payloads of the valid records, in file order (including those appended through this object).
  const std::vector<nlohmann::json>& records() const { return records_; }
  const JournalRecovery& recovery() const { return recovery_; }
  const std::string& path() const { return path_; }
  std::uint64_t size_bytes() const { return size_bytes_; }

 private:
  Journal() = default;
  void Close();

  int fd_ = -1;
  std::string path_;
  JournalLimits limits_;
  std::vector<nlohmann::json> records_;
  JournalRecovery recovery_;
  std::uint64_t size_bytes_ = 0;
  std::string failure_;  // set after an I/O error in Append: later appends are refused
};

// The valid records of a journal read without changing it (ReadJournal).
struct JournalContents {
  std::vector<nlohmann::json> records;
  // recovery.truncated(): the journal ends in a torn tail of recovery.dropped_bytes bytes at byte offset
  // recovery.valid_bytes, which Journal::Open (a resume) would truncate. It is left in place.
  JournalRecovery recovery;
};

// Reads and validates every record of the journal at `path` read-only, for an offline reader (calibrate):
// opens it O_RDONLY, takes no lock, creates nothing and truncates nothing. Damage and faulty writers are
// refused as in Open (kInvalidInput naming the record and byte offset); a torn tail is reported, not cut off.
// kInvalidInput for a missing file, one that is not a regular file or over the limits; kHardware for an I/O error.
Result<JournalContents> ReadJournal(const std::string& path, const JournalLimits& limits = JournalLimits());

// One framed journal line for `payload` (exposed for tests that build damaged journals).
std::string FrameJournalRecord(const std::string& payload);

}  // namespace selfcal::session
