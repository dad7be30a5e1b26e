// The rotation of a circle grid in each image, chosen from the robot poses (docs/detect.md, "Circle
// grids").
//
// A grid without an origin dot is named by FindCircleGrid (detection/circle_grid.h) only up to the
// rotations among its symmetries (180 deg; 90 deg too when square and symmetric). The rotation angle of
// the camera's motion between two images equals that of the flange's, whatever the hand-eye transform
// (cam_i_from_cam_j = flange_from_cam^-1 flange_i_from_flange_j flange_from_cam). Each candidate ordering
// of an image gives a camera rotation (cv::solvePnP, IPPE, on the layout's plane: the layout's points up to
// scale, which fix the rotation but are used for nothing else); a wrong rotation of the grid adds a turn
// about the board's normal to the camera motion, which changes its angle by far more than the poses' and
// the detector's errors. So, starting from the first image with a grid (as FindCircleGrid named it):
//   repeatedly, for every image not yet oriented and every candidate rotation, the median over the
//   oriented images of |angle(camera motion) - angle(flange motion)|; the image whose best candidate beats
//   its second best by the most is oriented by its best candidate, when that margin reaches
//   min_margin_deg;
//   an image left (no candidate clearly better) is refused (ok = false), its message naming the two
//   candidates' disagreements: its ids cannot be trusted.
// Joint-angle poses: the flange rotations of the nominal model's forward kinematics.
#pragma once

#include <vector>

#include "detection/detect_points.h"

namespace selfcal::detection {

struct GridOrientationOptions {
  double min_margin_deg = 10;
};

// Reorders the points of every circle-grid image of `points` (one per robot pose) as above; nothing for
// another detector or a grid whose only symmetric rotation is the identity. `setup` gives the camera
// (intrinsics and lens) and, for joint angles, the robot.
void OrientCircleGrids(const DetectionOptions& options, const std::vector<ImageRobotPose>& robot_poses,
                       const ObservationSetup& setup, std::vector<ImagePoints>* points,
                       const GridOrientationOptions& orientation = {});

}  // namespace selfcal::detection
