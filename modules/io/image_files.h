// Image files read for `selfcal detect`: every image as 8-bit grey through ViSP (vpImageIo, which converts
// colour the same way for every format), all of one size.
#pragma once

#include <string>
#include <vector>

#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::io {

struct NamedImage {
  std::string path;
  vpImage<unsigned char> image;
};

// Reads every file of `paths` in order. ErrorCode::kInvalidInput naming the file when one cannot be read
// or decoded, is empty, is larger than `max_bytes` or `max_pixels`, or differs in size from the first
// (naming both sizes).
Result<std::vector<NamedImage>> ReadGreyImages(const std::vector<std::string>& paths,
                                               std::size_t max_bytes = 256u << 20,
                                               std::size_t max_pixels = 100'000'000);

}  // namespace selfcal::io
