// Where the known dots should appear in a new settled frame (issue 12 item 1): the dots of the samples
// accepted so far are triangulated through the nominal robot model and camera, and projected from the
// new pose's joints, each with a 2x2 covariance. The gated naming itself is tracking/predicted_match.h;
// the session loop (session_pose.cc) corrects the raw predictions on the dots it tracked into the frame.
//
// Per dot seen in two samples or more: the linear least-squares point nearest to its rays in the base
// frame (each ray weighted by its lateral pixel noise at its depth, one reweighting), with the inverse of
// that normal matrix as covariance; projected with the covariance propagated to pixels plus the new
// frame's pixel noise. A dot seen in one sample only has a ray: it is put at the median depth (along the
// ray) of its nearest triangulated image neighbours in that sample, their depth spread (with a floor) as
// its uncertainty along the ray, which the projection turns into an elongated gate along the epipolar
// line. The neighbours' depths may also come from `current_px`, the dots already known in the new frame
// (tracked into it): a second view when only one sample has been accepted; they never enter a dot's own
// prediction, which rests on the accepted samples alone. Nothing here is iterative beyond one reweighting, and nothing is differentiated automatically.
#pragma once

#include <map>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "kinematics/robot_model.h"
#include "tracking/predicted_match.h"

namespace selfcal::acquisition {

// The nominal cell that predictions use: robot model, camera, centroid noise.
struct PredictionModel {
  RobotModel robot;
  CameraIntrinsics camera;
  double pixel_noise_px = 0.5;  // std per coordinate
};

// One accepted sample: the joints read with it and its named dot pixels.
struct ViewedSample {
  Eigen::VectorXd joints_rad;
  std::map<int, Eigen::Vector2d> dots_px;
};

struct DotPredictionOptions {
  int depth_neighbours = 6;             // single-ray dots: this many nearest triangulated neighbours...
  int min_depth_neighbours = 3;         // ...at least this many, else not predicted
  double min_depth_sigma_fraction = 0.03;  // floor of the depth std, as a fraction of the depth
  // Predictions outside the image by more than this are left out; those just outside still check a
  // tracked dot that jumped onto another blob as its own left the view.
  double image_margin_px = 1000;
  double max_gate_sigma_px = 15;        // the session names nothing by a gate longer than this (std)
};

struct DotPredictionReport {
  std::vector<tracking::PredictedDot> dots;  // in front of the camera and in the image
  int triangulated = 0;   // known dots with two rays or more
  int single_ray = 0;     // known dots predicted from one ray and their neighbours' depth
  int not_predicted = 0;  // known dots without a usable prediction (behind, outside, no depth)
};

// Predictions of every dot of `samples` in a frame taken at `joints_rad`, where the dots `current_px`
// are already known (may be empty).
DotPredictionReport PredictDots(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                const Eigen::VectorXd& joints_rad, const std::map<int, Eigen::Vector2d>& current_px,
                                const DotPredictionOptions& options);

}  // namespace selfcal::acquisition
