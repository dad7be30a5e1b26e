#include "session/journal.h"

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "base/atomic_file.h"
#include "base/crc32.h"
#include "session/file_util.h"
#include "session/session_test_util.h"

namespace selfcal::session {
namespace {

using testing::Contains;
using testing::ReadFile;
using testing::TempDir;
using testing::WriteFile;

nlohmann::json Record(int i) {
  return {{"type", "test"}, {"index", i}, {"text", "record number " + std::to_string(i)}};
}

// A journal at `path` holding Record(0) .. Record(count - 1); returns the file's bytes.
std::string WriteJournal(const std::string& path, int count) {
  Result<Journal> journal = Journal::Open(path);
  EXPECT_TRUE(journal.ok()) << journal.status().ToString();
  for (int i = 0; i < count; ++i) EXPECT_TRUE(journal.value().Append(Record(i)).ok());
  return ReadFile(path);
}

std::uintmax_t FileSize(const std::string& path) { return std::filesystem::file_size(path); }

TEST(JournalTest, RoundTrip) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  {
    Result<Journal> journal = Journal::Open(path);
    ASSERT_TRUE(journal.ok()) << journal.status().ToString();
    EXPECT_TRUE(journal->recovery().created);
    EXPECT_TRUE(journal->records().empty());
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(journal.value().Append(Record(i)).ok());
    EXPECT_EQ(journal->records().size(), 5u);
    EXPECT_EQ(journal->size_bytes(), FileSize(path));
  }
  Result<Journal> reopened = Journal::Open(path);
  ASSERT_TRUE(reopened.ok()) << reopened.status().ToString();
  EXPECT_FALSE(reopened->recovery().created);
  EXPECT_FALSE(reopened->recovery().truncated());
  EXPECT_EQ(reopened->recovery().valid_bytes, FileSize(path));
  ASSERT_EQ(reopened->records().size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(reopened->records()[i], Record(i));
  // Appending continues after the existing records.
  ASSERT_TRUE(reopened.value().Append(Record(5)).ok());
  EXPECT_EQ(Journal::Open(path)->records().size(), 6u);
}

TEST(JournalTest, LineFramingIsAsDocumented) {
  const std::string payload = R"({"type":"x"})";
  EXPECT_EQ(FrameJournalRecord(payload),
            "J1 0000000c " + Crc32Hex(Crc32(payload)) + " " + payload + "\n");
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  Result<Journal> journal = Journal::Open(path);
  ASSERT_TRUE(journal.value().Append({{"type", "x"}}).ok());
  EXPECT_EQ(ReadFile(path), FrameJournalRecord(payload));
}

TEST(JournalTest, TornTailAtEveryByteOffsetOfTheLastRecordIsDropped) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(dir.File("two.log"), 2);
  const std::string three = WriteJournal(dir.File("three.log"), 3);
  ASSERT_EQ(three.compare(0, two.size(), two), 0);
  for (std::size_t length = two.size(); length < three.size(); ++length) {
    SCOPED_TRACE("journal cut to " + std::to_string(length) + " of " + std::to_string(three.size()) + " bytes");
    WriteFile(path, three.substr(0, length));
    Result<Journal> journal = Journal::Open(path);
    ASSERT_TRUE(journal.ok()) << journal.status().ToString();
    ASSERT_EQ(journal->records().size(), 2u);
    EXPECT_EQ(journal->records()[0], Record(0));
    EXPECT_EQ(journal->records()[1], Record(1));
    EXPECT_EQ(journal->recovery().valid_bytes, two.size());
    EXPECT_EQ(journal->recovery().dropped_bytes, length - two.size());
    EXPECT_EQ(journal->recovery().truncated(), length > two.size());
    if (length > two.size()) {
      EXPECT_TRUE(Contains(journal->recovery().reason, "record 3 at byte offset " + std::to_string(two.size())))
          << journal->recovery().reason;
    }
    EXPECT_EQ(FileSize(path), two.size());  // truncated on disk
    // The next record starts on a record boundary.
    ASSERT_TRUE(journal.value().Append(Record(7)).ok());
    Result<Journal> again = Journal::Open(path);
    ASSERT_TRUE(again.ok()) << again.status().ToString();
    ASSERT_EQ(again->records().size(), 3u);
    EXPECT_EQ(again->records()[2], Record(7));
  }
}

TEST(JournalTest, GarbageAfterTheLastRecordIsATornTail) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  for (const std::string& garbage : {std::string(4096, '\0'), std::string("J1 zz"), std::string("\n\n")}) {
    WriteFile(path, two + garbage);
    Result<Journal> journal = Journal::Open(path);
    ASSERT_TRUE(journal.ok()) << journal.status().ToString();
    EXPECT_EQ(journal->records().size(), 2u);
    EXPECT_EQ(journal->recovery().dropped_bytes, garbage.size());
    EXPECT_EQ(FileSize(path), two.size());
  }
}

// A journal replaced or overwritten by text (several lines after the last valid record, none of them a
// record) is damage, not a torn tail: refused, and the file left as it was.
TEST(JournalTest, SeveralLinesOfTextAfterTheLastRecordAreRefusedNotCut) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  for (const std::string& prefix : {std::string(), two}) {
    const std::string text = prefix + "this is not a journal\n\x01\x02\x03 nor this";
    WriteFile(path, text);
    Result<Journal> journal = Journal::Open(path);
    ASSERT_FALSE(journal.ok());
    EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(journal.status().message(), "2 lines follow the last valid record"))
        << journal.status().message();
    EXPECT_EQ(FileSize(path), text.size());
  }
}

// A journal whose line ends an editor or git's autocrlf converted (CRLF or CR) was read as a torn tail of
// its first record: 0 records, and `calibrate` said "too few to calibrate". It is damage, refused at the
// first record, whatever the number of records.
TEST(JournalTest, ConvertedLineEndsAreRefusedAsDamage) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  for (int count : {1, 3}) {
    const std::string lf = WriteJournal(dir.File("lf" + std::to_string(count) + ".log"), count);
    for (const std::string& end : {std::string("\r\n"), std::string("\r")}) {
      std::string text;
      for (char c : lf) text += c == '\n' ? end : std::string(1, c);
      WriteFile(path, text);
      Result<Journal> journal = Journal::Open(path);
      ASSERT_FALSE(journal.ok()) << count << " records";
      EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
      EXPECT_TRUE(Contains(journal.status().message(), "journal " + path + ": record 1 at byte offset 0 ends with a "
                                                                           "carriage return"))
          << journal.status().message();
      EXPECT_EQ(FileSize(path), text.size());
    }
  }
}

// Issue 36's campaign: CR line ends and a first record whose length no longer ends at a carriage return
// (its header damaged too) left no newline in the file: the whole journal was taken as one torn record,
// and the session as empty.
TEST(JournalTest, RecordsSeparatedByCarriageReturnsAreNotATornTail) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string lf = WriteJournal(dir.File("lf.log"), 3);
  std::string text;
  for (char c : lf) text += c == '\n' ? '\r' : c;
  text[3] = text[3] == 'f' ? 'e' : 'f';  // the first record's length: its end is no longer the carriage return
  WriteFile(path, text);
  Result<Journal> journal = Journal::Open(path);
  ASSERT_FALSE(journal.ok()) << journal->records().size() << " records";
  EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(journal.status().message(), "journal " + path + ": record 1 at byte offset 0 is corrupt"))
      << journal.status().message();
  EXPECT_TRUE(Contains(journal.status().message(), "carriage return")) << journal.status().message();
  EXPECT_EQ(FileSize(path), text.size());
}

TEST(JournalTest, CorruptLastRecordIsATornTail) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(dir.File("two.log"), 2);
  std::string three = WriteJournal(path, 3);
  three[three.size() - 5] ^= 0x01;  // inside the last payload: CRC mismatch
  WriteFile(path, three);
  Result<Journal> journal = Journal::Open(path);
  ASSERT_TRUE(journal.ok()) << journal.status().ToString();
  EXPECT_EQ(journal->records().size(), 2u);
  EXPECT_TRUE(Contains(journal->recovery().reason, "CRC mismatch")) << journal->recovery().reason;
  EXPECT_EQ(FileSize(path), two.size());
}

TEST(JournalTest, FlippedByteInAMiddleRecordIsRefusedWithItsOffset) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string one = WriteJournal(dir.File("one.log"), 1);
  const std::string two = WriteJournal(dir.File("two.log"), 2);
  const std::string original = WriteJournal(path, 4);
  // Every byte of record 2: payload (CRC), header (framing, length, CRC field) and its newline.
  for (std::size_t at = one.size(); at < two.size(); ++at) {
    SCOPED_TRACE("byte " + std::to_string(at));
    std::string damaged = original;
    damaged[at] ^= 0x20;
    WriteFile(path, damaged);
    Result<Journal> journal = Journal::Open(path);
    ASSERT_FALSE(journal.ok());
    EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(journal.status().message(), "record 2 at byte offset " + std::to_string(one.size())))
        << journal.status().message();
    EXPECT_TRUE(Contains(journal.status().message(), path));
    EXPECT_EQ(ReadFile(path), damaged);  // nothing changed
  }
}

TEST(JournalTest, ARecordWithAValidCrcButABadPayloadIsRefusedEvenAtTheEnd) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  for (const std::string& payload : {std::string("[1,2]"), std::string(R"({"no_type":1})"), std::string("{oops")}) {
    WriteFile(path, two + FrameJournalRecord(payload));
    Result<Journal> journal = Journal::Open(path);
    ASSERT_FALSE(journal.ok()) << payload;
    EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(journal.status().message(), "record 3 at byte offset " + std::to_string(two.size())))
        << journal.status().message();
  }
}

// Issue 36: a record that gives a key twice was read with the last value winning.
TEST(JournalTest, ARecordThatGivesAKeyTwiceIsRefused) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  WriteFile(path, two + FrameJournalRecord(R"({"type":"fault","kind":"a","kind":"b"})"));
  Result<Journal> journal = Journal::Open(path);
  ASSERT_FALSE(journal.ok());
  EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(journal.status().message(), "record 3 at byte offset " + std::to_string(two.size()) +
                                                       " has a correct CRC but a bad payload (payload gives `kind` twice)"))
      << journal.status().message();
}

TEST(JournalTest, OversizeRecordsAreRefused) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  JournalLimits limits;
  limits.max_record_bytes = 100;
  Result<Journal> journal = Journal::Open(path, limits);
  ASSERT_TRUE(journal.ok());
  ASSERT_TRUE(journal.value().Append(Record(0)).ok());
  const auto size = FileSize(path);
  const Status refused = journal.value().Append({{"type", "big"}, {"text", std::string(200, 'x')}});
  EXPECT_EQ(refused.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(refused.message(), "exceeds the limit of 100 bytes")) << refused.message();
  EXPECT_EQ(FileSize(path), size);                      // nothing written
  EXPECT_TRUE(journal.value().Append(Record(1)).ok());  // and the journal stays usable

  // On reading, a record whose length exceeds the limit is damage when records follow it.
  const std::string big = FrameJournalRecord(R"({"type":"big","text":")" + std::string(200, 'x') + "\"}");
  WriteFile(path, big + FrameJournalRecord(R"({"type":"small"})"));
  Result<Journal> reread = Journal::Open(path, limits);
  ASSERT_FALSE(reread.ok());
  EXPECT_TRUE(Contains(reread.status().message(), "exceeds the limit")) << reread.status().message();
  EXPECT_TRUE(Contains(reread.status().message(), "record 1 at byte offset 0")) << reread.status().message();
}

TEST(JournalTest, FileSizeLimit) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  JournalLimits limits;
  limits.max_file_bytes = two.size() + 10;
  Result<Journal> journal = Journal::Open(path, limits);
  ASSERT_TRUE(journal.ok());
  const Status refused = journal.value().Append(Record(2));
  EXPECT_EQ(refused.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(refused.message(), "would exceed")) << refused.message();
  limits.max_file_bytes = two.size() - 1;
  Result<Journal> too_big = Journal::Open(path, limits);
  ASSERT_FALSE(too_big.ok());
  EXPECT_TRUE(Contains(too_big.status().message(), "more than the limit")) << too_big.status().message();
}

TEST(JournalTest, AppendNeedsATypedObjectAndReplacesInvalidUtf8) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  Result<Journal> journal = Journal::Open(path);
  EXPECT_THROW(journal.value().Append(nlohmann::json::array()), InvalidArgument);
  EXPECT_THROW(journal.value().Append({{"kind", "x"}}), InvalidArgument);
  ASSERT_TRUE(journal.value().Append({{"type", "fault"}, {"detail", "driver said \xff"}}).ok());
  const std::string replaced = "driver said \xef\xbf\xbd";  // U+FFFD
  EXPECT_EQ(journal->records()[0]["detail"], replaced);
  EXPECT_EQ(Journal::Open(path)->records()[0]["detail"], replaced);
}

TEST(JournalTest, DeeplyNestedPayloadsAreRefused) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  JournalLimits limits;
  limits.max_json_depth = 8;
  Result<Journal> journal = Journal::Open(path, limits);
  nlohmann::json deep = 1;
  for (int i = 0; i < 10; ++i) deep = nlohmann::json::array({deep});
  EXPECT_EQ(journal.value().Append({{"type", "deep"}, {"value", deep}}).code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(FileSize(path), 0u);
  WriteFile(path, FrameJournalRecord(R"({"type":"deep","v":[[[[[[[[[[1]]]]]]]]]]})"));
  Result<Journal> reread = Journal::Open(path, limits);
  ASSERT_FALSE(reread.ok());
  EXPECT_TRUE(Contains(reread.status().message(), "nested deeper")) << reread.status().message();
}

TEST(JournalTest, NotARegularFileIsRefused) {
  TempDir dir;
  Result<Journal> journal = Journal::Open(dir.path());
  ASSERT_FALSE(journal.ok());
  EXPECT_EQ(journal.status().code(), ErrorCode::kInvalidInput);
  Result<Journal> missing_dir = Journal::Open(dir.File("no/such/journal.log"));
  ASSERT_FALSE(missing_dir.ok());
  EXPECT_TRUE(Contains(missing_dir.status().message(), "no/such/journal.log"));
}

TEST(JournalTest, FullDiskAndIoErrorsAreHardwareFaults) {
  EXPECT_EQ(internal::ErrorCodeForErrno(ENOSPC), ErrorCode::kHardware);
  EXPECT_EQ(internal::ErrorCodeForErrno(EDQUOT), ErrorCode::kHardware);
  EXPECT_EQ(internal::ErrorCodeForErrno(EIO), ErrorCode::kHardware);
  EXPECT_EQ(internal::ErrorCodeForErrno(EACCES), ErrorCode::kInvalidInput);
  const Status from_atomic_write =
      Status::Error(ErrorCode::kInvalidInput, "cannot write x: write failed").WithDetail(kErrnoDomain, ENOSPC);
  EXPECT_EQ(internal::WithErrnoErrorCode(from_atomic_write).code(), ErrorCode::kHardware);
  // base/atomic_file.h carries the errno of a failed system call.
  const Status missing = ReadFileCapped("/nonexistent/selfcal/file", 10).status();
  EXPECT_STREQ(missing.detail_domain(), kErrnoDomain);
  EXPECT_EQ(missing.detail(), ENOENT);
  const Status no_errno = Status::Error(ErrorCode::kInvalidInput, "bad");
  EXPECT_EQ(internal::WithErrnoErrorCode(no_errno).code(), ErrorCode::kInvalidInput);
}

// A write that fails half-way (here: the file size limit of the process, EFBIG) leaves the journal a
// sequence of whole records and refuses later appends.
TEST(JournalTest, AFailedWriteIsCutOffAndLaterAppendsAreRefused) {
  TempDir dir;
  const std::string path = dir.File(kJournalFileName);
  const std::string two = WriteJournal(path, 2);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    Result<Journal> journal = Journal::Open(path);
    if (!journal.ok()) ::_exit(10);
    const rlimit limit{static_cast<rlim_t>(two.size() + 30), static_cast<rlim_t>(two.size() + 30)};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(11);
    const Status failed = journal.value().Append({{"type", "big"}, {"text", std::string(100, 'x')}});
    if (failed.ok() || !Contains(failed.message(), path)) ::_exit(12);
    if (journal.value().Append(Record(3)).ok()) ::_exit(13);  // refused: the journal must be reopened
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(ReadFile(path), two);  // the partial line was cut off
}

}  // namespace
}  // namespace selfcal::session
