// Chessboard inner corners as unknown points with ids that name the same physical corner in every image.
//
// Corners: cv::findChessboardCorners (adaptive threshold, normalised image) on a board of rows x cols
// inner corners, each refined by RefineCornerChecked (detection/corner_refine.h) along its two edges (the
// directions to its grid neighbours), out to 0.45 times the distance to its nearest neighbour, in a band of
// 1.5 px (narrow enough to miss a ChArUco marker's border beside the edge); where the small and the large
// window disagree by more than 1.5 px or the large one fails, the small window's corner, and where that
// fails too cv::cornerSubPix's with a window of 0.4 times the smallest corner spacing in the image (at most 11 px
// either side). The board's square size is not used. Pixels as tracking/dot_detector.h (origin at the
// centre of the top-left pixel; OpenCV's corner coordinates follow the same convention).
//
// Ids: corner (row, col) has id row * cols + col. OpenCV returns the grid in one of several orderings
// (a 9 x 6 board looks the same turned by 180 degrees, and OpenCV may start at either end), so each image's
// ordering is chosen among the symmetries of the rows x cols grid by three cues, in this order:
//   1. handedness: turning from the +col direction to the +row direction is counter-clockwise on screen
//      (as tracking/grid_identity.h): a view of the printed face keeps the board's handedness, so this
//      leaves the rotations of the grid (2 when rows != cols, 4 when square);
//   2. colour: the square between corners 0, 1, cols and cols + 1 is dark. The mean grey level of every
//      inner square's middle (25 samples over the central 40 % of the square) is taken; the dark squares
//      must be darker than the light ones by min_colour_contrast and at least 90 % of the squares must be
//      on their colour's side of the midpoint. When rows + cols is odd (a 9 x 6 board, whose corner squares
//      differ in colour) this fixes the ordering in every image on its own, without reference to other
//      images;
//   3. continuity (rows + cols even, or the colours cannot be told): of the orderings left, the one whose
//      corners lie nearest (RMS) the same ids in the previous image of the list; this assumes that
//      consecutive images move each corner by much less than half the board. For the first image, the
//      ordering that puts corner 0 nearest the image's top-left corner.
// The report says which cue decided.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::detection {

struct ChessboardOptions {
  int rows = 6;  // inner corners
  int cols = 9;
  double min_colour_contrast = 20;  // grey levels between the dark and the light squares
  int max_subpix_half_window_px = 11;
  Status Validate() const;
};

enum class OrderingCue { kNone, kColour, kContinuity, kFirstImage };
const char* OrderingCueName(OrderingCue cue);

struct ChessboardDetection {
  bool found = false;
  std::string message;                       // why not found
  std::vector<Eigen::Vector2d> corners_px;   // by id, rows * cols when found
  OrderingCue cue = OrderingCue::kNone;      // what chose the ordering
  double colour_contrast = 0;                // light minus dark squares' mean grey level (chosen ordering)
};

// A corner grid (OpenCV's row-major order of `rows` rows of `cols` corners) reordered by the cues above
// in `image`; `previous` (by id, or empty) is the previous image's corners. Throws InvalidArgument when
// corners.size() != rows * cols.
ChessboardDetection OrderChessboardCorners(const vpImage<unsigned char>& image, const std::vector<Eigen::Vector2d>& corners,
                                           const ChessboardOptions& options, const std::vector<Eigen::Vector2d>& previous);

// Finds, refines and orders the corners of `image`. Throws InvalidArgument on invalid options or an empty
// image.
ChessboardDetection DetectChessboard(const vpImage<unsigned char>& image, const ChessboardOptions& options,
                                     const std::vector<Eigen::Vector2d>& previous);

}  // namespace selfcal::detection
