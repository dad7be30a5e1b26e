// Lists of input files given as a directory or a glob (`selfcal detect --images DIR|GLOB`), and the key
// that matches an image to its pose file.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::io {

// The stem of a path: its file name without directory and last extension ("a/b/0.png" -> "0").
std::string FileStem(const std::string& path);

// What matches an image to its pose: the last run of decimal digits in the file name's stem, without
// leading zeros ("img_007.png" -> "7", "0.yaml" -> "0"); the whole stem when it has no digit.
std::string ImageKey(const std::string& path);

// The regular files of `spec`: every file directly in it whose name ends in one of `extensions`
// (lower-case, with the dot; compared case-insensitively) when `spec` is a directory, else the files
// matching the glob `spec` (any name). Sorted by ImageKey, numerically when both keys are numbers
// ("2" before "10"), then by path. ErrorCode::kInvalidInput naming `spec` and `what` ("images", "pose
// files") when nothing matches or the directory cannot be read.
Result<std::vector<std::string>> ListFiles(const std::string& spec, const std::vector<std::string>& extensions,
                                           const std::string& what);

// The extensions of the image files `ListFiles` takes from a directory: .png .jpg .jpeg .pgm .ppm .bmp
// .tif .tiff.
const std::vector<std::string>& ImageExtensions();

}  // namespace selfcal::io
