// Fuzz harness: a session manifest, session.json (docs/session-format.md), through session::ReadManifest
// of a temporary session folder. Refusals should name session.json:<line> (the lines of its keys come from
// base/json_lines.h).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "session/session_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = selfcal::fuzz::WriteFuzzFile("session.json", selfcal::fuzz::AsText(data, size));
  selfcal::Result<selfcal::session::SessionManifest> manifest = selfcal::session::ReadManifest(selfcal::fuzz::FuzzDir());
  if (!manifest.ok()) {
    selfcal::fuzz::NoteRefusal("manifest", manifest.status().message(), path + ":");
    return 0;
  }
  for (const selfcal::session::InputDigest& input : manifest->inputs) (void)manifest->FindInput(input.name);
  return 0;
}
