// Fuzz harness: session journal records (docs/session-format.md). Two readers per input:
//  1. the input as a raw journal file (framing, CRC, torn tail, damage) through session::ReadJournal;
//  2. each line of the input framed as one valid record (session::FrameJournalRecord, so the CRC passes
//     and the mutations reach the payloads), read back with ReadJournal and validated by ReadSessionLog.
// A refusal counts as naming the line when it names the record (`record <n>`).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "session/journal.h"
#include "session/samples.h"

namespace {

std::string FramedLines(const std::string& text) {
  std::string framed;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    framed += selfcal::session::FrameJournalRecord(text.substr(start, end - start));
    start = end + 1;
  }
  return framed;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = selfcal::fuzz::AsText(data, size);
  const std::string raw = selfcal::fuzz::WriteFuzzFile("raw.log", text);
  selfcal::Result<selfcal::session::JournalContents> contents = selfcal::session::ReadJournal(raw);
  if (contents.ok()) (void)selfcal::session::ReadSessionLog(contents->records);

  const std::string path = selfcal::fuzz::WriteFuzzFile("journal.log", FramedLines(text));
  contents = selfcal::session::ReadJournal(path);
  if (!contents.ok()) {
    selfcal::fuzz::NoteRefusal("journal", contents.status().message(), "record ");
    return 0;
  }
  selfcal::Result<selfcal::session::SessionLog> log = selfcal::session::ReadSessionLog(contents->records);
  if (!log.ok()) selfcal::fuzz::NoteRefusal("journal", log.status().message(), "record ");
  return 0;
}
