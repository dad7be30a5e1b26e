// The contact sheet of `selfcal detect`: one colour PNG with every image as a thumbnail and every point
// drawn with its id, so that a person can check at a glance that the ids name the same physical point in
// every image (docs/detect.md).
//
// Layout: a header line (what the marks mean), then the images in rows of `columns` tiles (0: about a
// square sheet), each scaled to at most max_tile_width_px wide, under a title line "name: ok, N points"
// (green) or "name: FAILED" (red; failed_label); a failed image's tile carries the label and the reason
// (ImagePoints::message, wrapped, at most 5 lines) in red on a darkened band across its top. Marks: a green circle and the id in yellow at every point; point 0 in a
// larger red circle; with grid_cols > 0 (a grid or chessboard), a red arrow from point 0 to point 1 (+col)
// and a blue one from point 0 to point grid_cols (+row). Pixels as tracking/dot_detector.h.
#pragma once

#include <string>
#include <vector>

#include <visp3/core/vpImage.h>

#include "base/status.h"
#include "detection/detect_points.h"

namespace selfcal::detection {

struct SheetImage {
  std::string title;                               // e.g. the image's file name
  const vpImage<unsigned char>* image = nullptr;
  const ImagePoints* points = nullptr;
};

struct ContactSheetOptions {
  int max_tile_width_px = 640;
  int columns = 0;    // 0: ceil(sqrt(number of images))
  int grid_cols = 0;  // > 0: draw the +col and +row arrows from point 0
  std::string failed_label = "FAILED";  // the outcome of an image without points ("SKIPPED": left out)
};

// The sheet as PNG bytes. kInvalidInput when there is no image, an image is empty, or the PNG cannot be
// encoded.
Result<std::string> ContactSheetPng(const std::vector<SheetImage>& images, const ContactSheetOptions& options);

}  // namespace selfcal::detection
