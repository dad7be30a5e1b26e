// Fuzz harness: a URDF (docs/urdf.md) through urdf::ParseUrdfRobot, in memory: the non-recursive scan
// (depth and size limits), tinyxml and urdfdom, the chain and its KDL check (20 samples here). Refusals
// should name fuzz.urdf:<line>.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "fuzz/fuzz_support.h"
#include "urdf/urdf_robot.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "fuzz.urdf";
  selfcal::urdf::FkCheckOptions check;
  check.samples = 20;
  const selfcal::Result<selfcal::urdf::UrdfRobot> robot = selfcal::urdf::ParseUrdfRobot(
      selfcal::fuzz::AsText(data, size), kName, {"base_link", "tool0", "camera_optical_frame"}, std::nullopt, check);
  if (!robot.ok()) selfcal::fuzz::NoteRefusal("urdf", robot.status().message(), std::string(kName) + ":");
  return 0;
}
