// Fuzz harness: a robot config or calibrated-model file (docs/calibrated-model-format.md) through
// io::ParseRobotModelText. Refusals should name fuzz.yaml:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/robot_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "fuzz.yaml";
  selfcal::Result<selfcal::RobotModel> model = selfcal::io::ParseRobotModelText(selfcal::fuzz::AsText(data, size), kName);
  if (!model.ok()) selfcal::fuzz::NoteRefusal("robot_config", model.status().message(), std::string(kName) + ":");
  return 0;
}
