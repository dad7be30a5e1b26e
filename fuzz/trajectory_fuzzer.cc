// Fuzz harness: a trajectory or plan file (docs/trajectory-format.md) through io::LoadTrajectoryFile for a
// 6-joint robot, from a temporary file. Refusals should name <file>:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/trajectory_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = selfcal::fuzz::WriteFuzzFile("plan.yaml", selfcal::fuzz::AsText(data, size));
  selfcal::Result<selfcal::io::TrajectoryFile> file = selfcal::io::LoadTrajectoryFile(path, 6);
  if (!file.ok()) {
    selfcal::fuzz::NoteRefusal("trajectory", file.status().message(), path + ":");
    return 0;
  }
  selfcal::planning::PlanSubject subject = selfcal::io::PlanSubjectOf(*file);
  (void)subject;
  return 0;
}
