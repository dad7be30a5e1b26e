// Fuzz harness: a session's setup.json (docs/session-format.md) through session::ParseSetupFile.
// Refusals should name setup.json:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "session/setup_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "setup.json";
  selfcal::ObservationSet set;
  selfcal::session::SetupNaming naming;
  selfcal::Status status = selfcal::session::ParseSetupFile(selfcal::fuzz::AsText(data, size), kName, &set, &naming);
  if (!status.ok()) selfcal::fuzz::NoteRefusal("setup", status.message(), std::string(kName) + ":");
  return 0;
}
