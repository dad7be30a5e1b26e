// Fuzz harness: an observations file (docs/observations-format.md) through the strict YAML reader and
// io::ParseObservations. Any crash, sanitizer report, hang or uncaught exception is a defect; a refusal is
// the expected answer to a bad file and should name fuzz.yaml:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/observations_file.h"
#include "yaml/yaml_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* kName = "fuzz.yaml";
  selfcal::Result<selfcal::yaml::YamlDocument> doc = selfcal::yaml::ParseYamlText(selfcal::fuzz::AsText(data, size), kName);
  if (!doc.ok()) {
    selfcal::fuzz::NoteRefusal("observations", doc.status().message(), std::string(kName) + ":");
    return 0;
  }
  selfcal::Result<selfcal::ObservationSet> set = selfcal::io::ParseObservations(*doc);
  if (!set.ok()) selfcal::fuzz::NoteRefusal("observations", set.status().message(), std::string(kName) + ":");
  return 0;
}
