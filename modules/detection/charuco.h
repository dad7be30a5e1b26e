// ChArUco board corners: the inner chessboard corners of a board whose light squares hold ArUco markers,
// named by the markers, so that a partly seen board names the same physical corner by the same id in every
// image.
//
// Board: cols x rows squares (OpenCV's squaresX x squaresY: "a 5x7 board" is 5 squares along x, 7 along y),
// the markers of one of OpenCV's predefined
// dictionaries (by name, e.g. DICT_6X6_250) in the light squares, laid out as cv::aruco::CharucoBoard
// lays them out (OpenCV 4.6: marker ids 0, 1, ... in the light squares row by row). The board's metric
// geometry (square and marker length) is not used: selfcal's scene points are unknowns, and the markers'
// centres (the squares' centres whatever the marker size) are enough to find the corners.
//
// Ids: OpenCV's ChArUco corner ids (cv::aruco::CharucoBoard::chessboardCorners): the (rows - 1) x
// (cols - 1) inner corners, id = row * (cols - 1) + col in the board's frame.
//
// Steps per image:
//   1. markers: cv::aruco::detectMarkers with OpenCV's default parameters; ids not on the board are dropped;
//   2. prediction: each inner corner with at least one of its two diagonal neighbour squares' markers
//      found is predicted by the homography from the board positions to the image positions of the
//      centres (intersection of the marker's diagonals, exact under perspective) of the found markers
//      within 2.5 squares of it (at least 4; least squares), local so that lens distortion across the
//      board does not enter;
//   3. refinement: RefineCornerChecked (detection/corner_refine.h) along the corner's two edges (their
//      directions from the same homography), out to 0.45 times the square's side in the image, in a band
//      kept clear of the neighbour markers' borders (their nearest corners' distance / sqrt(2), less 1.5 px
//      and the smoothing's reach; 1 to 3 px). A corner is dropped when its refinement does not converge,
//      moves farther than a fifth of a square from its prediction, or disagrees by more than 1.5 px with
//      the refinement on a 3 px disc (something else inside the large window: the kvasios recorder's axes
//      drawn over a corner).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::detection {

// OpenCV's predefined dictionaries' names (DICT_4X4_50 ... DICT_APRILTAG_36h11), in OpenCV's order.
const std::vector<std::string>& CharucoDictionaryNames();
// The number of markers of a named dictionary; kInvalidInput naming every valid name otherwise.
Result<int> CharucoDictionarySize(const std::string& name);

struct CharucoOptions {
  std::string dictionary = "DICT_6X6_250";
  int rows = 7;  // squares along the board's y (OpenCV's squaresY)
  int cols = 5;  // squares along x (squaresX)
  double min_radius_px = 1.5;  // a corner whose window would be smaller is dropped
  // Every problem, one per line (kInvalidInput): an unknown dictionary (naming the valid ones), fewer
  // than 2 x 2 squares, more markers than the dictionary holds.
  Status Validate() const;
};

struct CharucoDetection {
  bool found = false;  // at least one corner
  std::string message;
  std::map<int, Eigen::Vector2d> corners_px;  // id -> pixel
  int markers = 0;                            // board markers found
  int predicted = 0;                          // corners predicted from them (step 2)
};

// Throws InvalidArgument on invalid options or an empty image.
CharucoDetection DetectCharuco(const vpImage<unsigned char>& image, const CharucoOptions& options);

}  // namespace selfcal::detection
