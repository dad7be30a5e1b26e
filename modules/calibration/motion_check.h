// A check of recorded flange poses against the images that needs no known distance and assumes no
// hand-eye transform: the camera motions the images alone give (bundle/free_camera_bundle.h: every
// camera free, started from the hand-eye solution) against the recorded flange motions. The rotation
// angle of a relative motion is the same for the flange and for a camera rigidly on it, whatever the
// hand-eye transform, so per pair of poses |angle(cam_i^-1 cam_j) - angle(flange_i^-1 flange_j)| is the
// disagreement of images and controller: lens model errors, a pose logged at the wrong time, a flange
// pose of the wrong frame.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bundle/free_camera_bundle.h"
#include "geometry/rigid3.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct MotionPair {
  std::string pose_a, pose_b;
  double flange_angle_rad = 0, camera_angle_rad = 0;
  double error_rad = 0;  // |camera - flange|
};

// One image's own camera pose beside the model's. base_from_cam_images is the free-camera bundle's, solved
// from the images alone (its gauge: the first camera held at the model's, the distance of the first two
// held), moved by the one rigid transform that best aligns all the images' cameras with the model's (the
// chordal mean of R_model R_images^T, then the mean of the centres' differences), so that no single image
// carries the gauge. base_from_cam_model is the model's: base_from_flange * flange_from_cam.
struct ImageCameraPose {
  std::string pose_id;
  Rigid3 base_from_cam_images, base_from_cam_model;
  double translation_error_m = 0;  // |centre (images) - centre (model)|, m
  double rotation_error_rad = 0;   // angle of R_model^T R_images, rad
};

struct MotionCheck {
  bool ok = false;
  std::string message;
  bundle::FreeCameraReport images;  // the free-camera bundle
  std::vector<MotionPair> pairs;    // every pair of the poses it solved
  std::vector<ImageCameraPose> cameras;  // every pose it solved, in the order of obs.poses
  double median_error_rad = 0, p90_error_rad = 0, max_error_rad = 0;
  int pairs_over_2deg = 0;
};

// Every pose of the flange-pose set `obs` (identification and verification), started at
// base_from_flange * flange_from_cam with the dots given and the intrinsics of obs.camera (e.g. the
// hand-eye bundle's dots and calibrated camera). Eye-to-hand (obs.robot.mount) hand_eye is the fixed camera
// base_from_cam, the start base_from_flange^-1 * base_from_cam and the cameras are in the flange frame (the
// dots' frame); the angle of a camera motion is still the flange motion's.
MotionCheck CheckImageMotions(const ObservationSet& obs, const Rigid3& hand_eye,
                              const std::map<int, Eigen::Vector3d>& dots_in_base, const bundle::FreeCameraOptions& options);

}  // namespace selfcal::calibration
