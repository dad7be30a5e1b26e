// Module-internal: the blob ViSP's vpDot2::track finds for DetectDots (dot_detector.h) and TrackDots
// (dot_tracker.h), with MakeDarkDot's settings (grey levels [0, T], vpDot2's own size and ellipsoid checks
// off): its bounding box, centre of gravity and area, which is all this module uses of vpDot2.
//
// vpDot2::track first follows the border of the blob under its start point (vpDot2::computeParameters: a
// run to the right from the start pixel to the blob's edge, then the Freeman chain around the blob, the
// area and first moments of the polygon through the border pixel centres summed step by step from float
// increments). Only when that fails (start pixel not dark, the run longer than width / 0.651, a single
// pixel, a polygon of area 0 or 1, no dark pixel on the centre's row and column, a centre outside the
// image) does it search a window of 5 x the previous size, or throw. FollowBorder reproduces the first
// part operation for operation (the same float increments added in the same order: the same bits)
// without vpDot2's two list nodes per border step, and TrackDarkBlob hands every other case to vpDot2
// itself, which fails the same way and then searches or throws. blob_trace_test.cc checks the two
// against vpDot2 alone.
#pragma once

#include <Eigen/Core>
#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImage.h>

#include "tracking/dot_detector.h"

namespace selfcal::tracking::internal {

// What vpDot2 reports of a blob.
struct TracedBlob {
  PixelBox bbox;                                  // vpDot2::getBBox(), inclusive
  Eigen::Vector2d cog_px = Eigen::Vector2d::Zero();  // vpDot2::getCog() (u, v)
  double polygon_area_px2 = 0;                    // vpDot2::getArea()
};

// vpDot2::track's result when its first border following succeeds, in *out; false when vpDot2 would
// search a window or throw instead. `start` is the dot's centre of gravity before track (u, v), `width`
// its width (0: none, as initTracking's size 0).
bool FollowBorder(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start, double width,
                  TracedBlob* out);

// vpDot2::track on MakeDarkDot(threshold) with centre of gravity `start` and the given width and height
// (0 x 0 for initTracking's size 0): FollowBorder, else vpDot2 itself. Throws vpDot2's vpException.
TracedBlob TrackDarkBlob(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start,
                         double width, double height);

// The same with vpDot2 alone (the reference of the tests).
TracedBlob TrackDarkBlobWithVpDot2(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start,
                                   double width, double height);

// A vpDot2 configured for dark blobs at levels [0, threshold] with vpDot2's own size and ellipsoid checks
// off (MeasureBlob applies counted equivalents) and moments on.
vpDot2 MakeDarkDot(int threshold);

}  // namespace selfcal::tracking::internal
