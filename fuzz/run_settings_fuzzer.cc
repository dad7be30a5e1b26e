// Fuzz harness: a session's run.json (docs/session-format.md) through simulation::ReadRunBackends and
// simulation::SimCellOptionsFor, as `selfcal audit` reads it. Refusals should name run.json:<line> (the
// lines of its keys come from base/json_lines.h).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "simulation/sim_run_settings.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "run.json";
  const std::string text = selfcal::fuzz::AsText(data, size);
  const selfcal::Result<selfcal::simulation::RunBackends> backends = selfcal::simulation::ReadRunBackends(text, kName);
  if (!backends.ok()) {
    selfcal::fuzz::NoteRefusal("run_settings", backends.status().message(), std::string(kName) + ":");
    return 0;
  }
  const selfcal::Result<selfcal::simulation::SimCellOptions> options =
      selfcal::simulation::SimCellOptionsFor(text, kName);
  if (!options.ok()) selfcal::fuzz::NoteRefusal("run_settings", options.status().message(), std::string(kName) + ":");
  return 0;
}
