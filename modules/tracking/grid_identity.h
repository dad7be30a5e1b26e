// Dot identities from one image of a planar R x C dot grid, without tracking (../shared/RELIABILITY.md D5, D6).
//
// Id convention (the ROS-Industrial "modified circle grid": one larger dot marks the origin):
//
//      row R-1  o  o  o  o        Target frame, seen from the front (the printed side):
//        ...    o  o  o  o          origin at the centre of the larger dot,
//      row 1    o  o  o  o          +x along row 0 (columns increase), +y along column 0 (rows
//      row 0    O  o  o  o          increase), +z out of the printed face towards the viewer.
//             col 0  1 ... C-1     Dot (row, col) is at (col * spacing, row * spacing, 0); id = row * C + col.
//
// This is industrial_calibration's ModifiedCircleGridTarget frame (big dot bottom-left, x along the bottom
// row, y up the page, z out of the page); its point index is (R - 1 - row) * C + col, not our id.
//
// In the image: a view of the printed face preserves its handedness, so turning from the +col direction to
// the +row direction is counter-clockwise on screen: with d_col, d_row the image steps to the next column
// and the next row, d_col.u * d_row.v - d_col.v * d_row.u < 0 (v points down). The larger dot fixes which
// corner is the origin; this handedness fixes which of its two grid lines is row 0. Seen from behind (a
// mirrored image) the rows and columns come out swapped; with R != C that is refused (kWrongSize), with
// R == C it cannot be told from the dots alone.
//
// Without an origin marker (OriginMarker::kNone, e.g. a symmetric calibration grid) the same handedness
// is used and the origin is the corner nearest the image's top-left (smallest u + v) among the corners
// compatible with R x C: ids are then defined only up to the grid's symmetry (4 rotations when R == C, 2
// otherwise) and the report says so (orientation_from_marker = false, D5).
//
// Method: lattice growth. A seed dot near the middle of the detections, its nearest neighbour and the
// nearest one at 45-135 degrees from it give two lattice steps, confirmed by the dot that closes the 2 x 2
// cell. Positions next to the assigned ones are predicted with a homography fitted to the assigned dots
// within two cells (all assigned dots when too few are near) and take the only detection within
// match_tolerance of the local spacing; two detections within it, or two positions claiming one
// detection, are an ambiguity and the result is refused. Growth is not bounded by R x C, so a lattice
// larger than configured is seen and refused.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "tracking/dot_detector.h"

namespace selfcal::tracking {

enum class OriginMarker { kLargerDot, kNone };

struct GridIdentityOptions {
  int rows = 10;
  int cols = 10;
  OriginMarker origin_marker = OriginMarker::kLargerDot;
  // The origin dot's area over the median area of its lattice neighbours must reach this (nominally
  // (20 mm / 10 mm)^2 = 4 on the ROS-Industrial target)...
  double min_origin_area_ratio = 2.0;
  // ...and every other dot's ratio must stay below this, else the origin is ambiguous (D5).
  double max_runner_up_area_ratio = 1.5;
  double match_tolerance = 0.3;      // fraction of the local dot spacing
  // Every dot to the homography of the whole grid, as a fraction of the median dot spacing in the image.
  // A dot on the wrong cell is about one spacing off; lens distortion moves corner dots by a few pixels
  // (up to 0.15 spacing on ros-industrial image 2, whose grid fills an image corner).
  double max_residual_spacing = 0.25;
  bool require_complete = true;      // all R x C dots; false accepts a partial grid (marker required)
  int max_seed_attempts = 10;

  Status Validate() const;
};

enum class GridOutcome {
  kNotRun,
  kSuccess,
  kTooFewDots,        // fewer detections than needed
  kNoLattice,         // no seed gave a 2 x 2 lattice cell
  kAmbiguousMatch,    // a predicted position had two detections, or two positions one detection (D6)
  kWrongSize,         // the lattice found does not fit R x C from the origin (too large, swapped, mirrored)
  kIncomplete,        // fewer than R x C dots assigned with require_complete
  kNoOriginDot,       // no dot clearly larger than its neighbours
  kAmbiguousOrigin,   // more than one candidate origin (D5)
  kOriginNotAtCorner, // the larger dot is not at a corner of the lattice
  kLargeResidual,     // some dot is further than max_residual_spacing from the grid's homography
};
const char* GridOutcomeName(GridOutcome outcome);

struct GridDot {
  int id = -1;
  int row = -1;
  int col = -1;
  int detection_index = -1;  // into the detections passed in
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();
  double residual_px = 0;    // to image_from_grid
};

struct GridIdentityReport {
  GridOutcome outcome = GridOutcome::kNotRun;
  std::string message;                  // why, in words
  std::vector<GridDot> dots;            // sorted by id; on success only
  // Homography from grid coordinates (col, row) (units: one spacing) to pixels, fitted to every dot.
  Eigen::Matrix3d image_from_grid = Eigen::Matrix3d::Identity();
  double rms_residual_px = -1;
  double max_residual_px = -1;
  double median_spacing_px = -1;        // median distance between neighbouring dots in the image
  bool orientation_from_marker = false; // false: ids only up to the grid's symmetry
  int origin_detection_index = -1;
  double origin_area_ratio = 0;         // the origin's area over its neighbours' median (marker only)
  double runner_up_area_ratio = 0;      // the largest such ratio among the other dots
  int assigned = 0;                     // detections on the lattice
  int unassigned_detections = 0;        // detections left off it (spurious blobs, other targets)
};

// Assigns grid ids to `detections` (see the header comment). Throws InvalidArgument on invalid options
// or a non-finite centroid (D7).
GridIdentityReport IdentifyGrid(const std::vector<DotDetection>& detections, const GridIdentityOptions& options);

// The target-frame position of dot (row, col) in metres for the given spacing: (col s, row s, 0).
Eigen::Vector3d GridPointInTarget(int row, int col, double spacing_m);

}  // namespace selfcal::tracking
