// Shared by the fuzz harnesses (fuzz/*_fuzzer.cc) and their regression driver (fuzz/regression_main.cc).
//
// - FuzzDir(): one private temporary directory per process (removed at exit), for the readers that take a
//   path (LoadTrajectoryFile, LoadCameraFile, ReadManifest, ReadJournal).
// - NoteRefusal(): counts the refusals of a harness and how many name the line of the input
//   (`<file>:<line>`, or for journal records `record <n>`). With SELFCAL_FUZZ_STATS=<file> in the environment the counts are appended to that
//   file at exit, one line `<harness> refusals=N with_line=M` (scripts/fuzz reads it); without it nothing
//   is counted or written. SELFCAL_FUZZ_SHOW=1 as well prints each counted refusal that names no line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace selfcal::fuzz {

// The input as text (bytes unchanged, NUL bytes included).
inline std::string AsText(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// The process's temporary directory (created on first use, mode 0700, removed with its files at exit).
const std::string& FuzzDir();

// Writes `bytes` to FuzzDir()/name, replacing it; returns the full path. Aborts when it cannot (a harness
// that silently tests nothing is worse than one that stops).
std::string WriteFuzzFile(const std::string& name, const std::string& bytes);

// Counts one refusal of `harness` whose message is `message`; it names the line when it contains
// `line_prefix` followed by a digit (`line_prefix` is e.g. "fuzz.yaml:" or "record ").
void NoteRefusal(const char* harness, const std::string& message, const std::string& line_prefix);

}  // namespace selfcal::fuzz
