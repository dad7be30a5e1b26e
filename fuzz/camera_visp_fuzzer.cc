// Fuzz harness: a ViSP vpXmlParserCamera file (docs/camera-files.md) through selfcal's strict XML reader
// io::ParseVispCameraXml, in memory. Refusals should name fuzz.xml:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/camera_xml.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "fuzz.xml";
  selfcal::Result<selfcal::CameraIntrinsics> camera =
      selfcal::io::ParseVispCameraXml(kName, selfcal::fuzz::AsText(data, size), "");
  if (!camera.ok()) selfcal::fuzz::NoteRefusal("camera_visp", camera.status().message(), std::string(kName) + ":");
  return 0;
}
