// Module-internal: the pixels around one traced blob, classified for MeasureBlob (blob_analysis.h) into the
// blob's own pixels, the pixels of other dark blobs with a one-pixel rim (kept out of the background ring
// and of the weighted centroid), and the free background. Pixel conventions as dot_detector.h.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <visp3/core/vpImage.h>

#include "tracking/dot_detector.h"

namespace selfcal::tracking::internal {

enum Cell : std::uint8_t { kFree = 0, kBlob = 1, kOther = 2 };

// The blob's bounding box dilated by a margin and clipped to the image; one cell per pixel, row by row.
struct BlobWindow {
  int u0 = 0, v0 = 0, w = 0, h = 0;
  std::vector<std::uint8_t> cells;
  bool Contains(int u, int v) const { return u >= u0 && v >= v0 && u < u0 + w && v < v0 + h; }
  std::uint8_t At(int u, int v) const { return cells[static_cast<size_t>((v - v0) * w + (u - u0))]; }
  const std::uint8_t* Row(int v) const { return &cells[static_cast<size_t>((v - v0) * w)]; }  // image row v
};

// Blob pixels on image row v, columns u_begin..u_end (inclusive).
struct PixelRun {
  int v = 0, u_begin = 0, u_end = -1;
};

// Classifies the window of `bbox` dilated by `margin`. Dark: I <= threshold. The blob: the 8-connected
// dark pixels inside the bbox of the one component (at most one can) that spans the whole bbox, holding
// `required_seed` (u, v) when given, else reached from the bbox's top row. Other: every other dark pixel
// of the window, and every non-blob pixel 8-adjacent to one. False when there is no such blob (the window
// is then unspecified). The blob's runs, in raster order, go to *blob_runs.
//
// The dark runs of the bbox's rows are labelled as in dark_components.cc (one union-find over runs, the
// span of each set kept at its root) where a pixel-by-pixel flood fill from each seed was used before;
// blob_window_test.cc checks both give the same cells.
bool ClassifyBlobWindow(const vpImage<unsigned char>& image, int threshold, const PixelBox& bbox, int margin,
                        const std::pair<int, int>* required_seed, BlobWindow* window,
                        std::vector<PixelRun>* blob_runs);

}  // namespace selfcal::tracking::internal
