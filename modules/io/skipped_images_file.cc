#include "io/skipped_images_file.h"

#include <sstream>

#include "base/atomic_file.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

std::string SkippedImagesText(const SkippedImages& list) {
  std::ostringstream out;
  out << "format: selfcal-skipped-images\nversion: 1\n"
      << "observations: " << YamlQuoted(list.observations) << "\n"
      << "images: " << list.images << "\n"
      << "kept: " << list.kept << "\n"
      << "skipped:" << (list.skipped.empty() ? " []" : "") << "\n";
  for (const SkippedImage& s : list.skipped) {
    out << "  - {pose: " << YamlQuoted(s.pose_id) << ", image: " << YamlQuoted(s.image)
        << ", reason: " << YamlQuoted(s.reason) << "}\n";
  }
  return out.str();
}

Status SaveSkippedImages(const SkippedImages& list, const std::string& path) {
  return WriteFileAtomically(path, SkippedImagesText(list));
}

}  // namespace selfcal::io
