// Circle grids without an origin dot (OpenCV's symmetric and asymmetric calibration grids), their dots
// named by cv::findCirclesGrid (docs/detect.md, "Circle grids").
//
// Layout (OpenCV's): a grid of `rows` rows of `cols` dots. Symmetric: dot (r, c) at (c, r) in units of the
// spacing; asymmetric: at (2 c + r mod 2, r), every other row shifted by half a step. id = r * cols + c.
// The layout serves only to name the dots: selfcal never uses it as known 3-D points.
//
// Candidates are tracking's dots (detection/blob_candidates.h: either polarity, texture left out), handed
// to cv::findCirclesGrid as points (no blob detector of its own), so the centres are the intensity-weighted
// centroids of tracking/dot_detector.h. OpenCV returns the grid in one of the orderings the layout's
// symmetries allow (a symmetric grid turned by 180 deg, by 90 deg or transposed when square; an
// asymmetric one by 180 deg when its rows are even in number). Of these, FindCircleGrid keeps:
//   1. handedness (when the layout has mirror symmetries): turning from the +x to the +y direction of the
//      layout is counter-clockwise on screen, as tracking/grid_identity.h and detection/chessboard.h;
//   2. of the rotations left, the one with dot 0 nearest the image's top-left corner (smallest u + v).
// Step 2 names a grid consistently only while the camera does not turn by much between images; the
// rotation of each image is then chosen from the robot poses (detection/grid_orientation.h).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "tracking/dot_detector.h"

namespace selfcal::detection {

struct CircleGridLayout {
  int rows = 0;
  int cols = 0;
  bool asymmetric = false;
  int size() const { return rows * cols; }
  Eigen::Vector2d Point(int id) const;  // layout coordinates of dot `id` (units of the spacing)
};

// A symmetry of the layout: the map about its centre that takes dot k onto dot perm[k]; a rotation by
// angle_rad (about the layout's normal), or a mirror.
struct LayoutSymmetry {
  std::vector<int> perm;
  bool rotation = true;
  double angle_rad = 0;
};
// Every symmetry of the layout among the 8 rotations and mirrors of the square lattice, the identity
// first.
std::vector<LayoutSymmetry> LayoutSymmetries(const CircleGridLayout& layout);

struct CircleGridDetection {
  bool found = false;
  std::string message;                     // why not found, or how the ordering was chosen
  std::vector<Eigen::Vector2d> centres_px;  // by id, layout.size() when found
  std::vector<double> contrast;            // by id: the dot's contrast (grey levels)
};

// The grid among `dots` (see above). Throws InvalidArgument on a layout of fewer than 2 x 2 dots.
CircleGridDetection FindCircleGrid(const std::vector<tracking::DotDetection>& dots, const CircleGridLayout& layout);

}  // namespace selfcal::detection
