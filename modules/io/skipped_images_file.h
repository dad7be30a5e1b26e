// The images `selfcal detect --skip-failed` left out, beside the observations file it wrote
// (format `selfcal-skipped-images`, version 1, docs/detect.md): for a script that needs to know which
// images are missing from the observations and why, without reading detect's stdout.
//
//   format: selfcal-skipped-images
//   version: 1
//   observations: "obs.yaml"        # the observations file written with it, as given on the command line
//   images: 15                      # images read
//   kept: 13                        # poses in the observations file
//   skipped:                        # in image order; [] when none was left out
//     - {pose: "3", image: "images/3.png", reason: "grid not identified (no_lattice): ..."}
#pragma once

#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::io {

struct SkippedImage {
  std::string pose_id;  // the id the pose would have had in the observations file
  std::string image;    // the image file, as read
  std::string reason;   // why it gave no points
};

struct SkippedImages {
  std::string observations;  // the observations file written beside this one
  int images = 0;            // images read
  int kept = 0;              // poses written
  std::vector<SkippedImage> skipped;
};

// The file's text (every string quoted, so an id like `3` or `yes` stays a string).
std::string SkippedImagesText(const SkippedImages& list);

// Writes it atomically (base/atomic_file.h).
Status SaveSkippedImages(const SkippedImages& list, const std::string& path);

}  // namespace selfcal::io
