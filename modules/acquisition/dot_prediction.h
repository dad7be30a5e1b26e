// Where the known dots should appear in a new settled frame (issue 12 item 1): the dots of the samples
// accepted so far are triangulated through the nominal robot model and camera, and projected from the
// new pose's joints, each with a 2x2 covariance. The gated naming itself is tracking/predicted_match.h;
// the session loop (session_pose.cc) corrects the raw predictions on the dots it tracked into the frame.
//
// Per dot seen in two samples or more: the linear least-squares point nearest to its rays in the base
// frame (each ray weighted by its lateral pixel noise at its depth, one reweighting), with the inverse of
// that normal matrix as covariance; projected with the covariance propagated to pixels plus the new
// frame's pixel noise. A dot seen in one sample only has a ray, and may lie anywhere on it within the
// depth range of the scene that sample saw (its triangulated dots, with a margin): its prediction is that
// segment of its epipolar line, as an elongated gate that holds the whole segment. Neighbours in the
// image say nothing about a dot's depth in a scene of scattered dots (the nearest-neighbour depth that
// stood here named 15 of 80 simulated sessions wrongly). The depth range may also come from
// `current_px`, the dots already known in the new frame (tracked into it): a second view when only one
// sample has been accepted; they never enter a dot's own prediction, which rests on the accepted samples
// alone. The nominal model puts each sample's camera a little off, differently at every pose; before the
// points are triangulated, each sample's camera is resected on the points triangulated from all samples
// (cv::solvePnP from the nominal pose, a few rounds; the first sample holds the gauge), so that a point
// seen from distant poses lands where the dots around it do, and the new frame's camera is resected on
// the dots known in it. A resected pose, unlike a planar map of pixels, keeps the parallax of a dot
// nearer or farther than the scene's middle. Cameras known better (bundled_cameras.h: the samples'
// cameras and f_x from a bundle of their images, which the session loop gives) are used as given. Nothing
// here is iterative beyond those rounds and one reweighting, and nothing is differentiated automatically.
//
// "Base" below is the frame of the points (kinematics/robot_model.h, PointsFromCam): the robot base in
// eye-in-hand, the flange in eye-to-hand, where the fixed camera sees the dots the flange carries; every
// sample's nominal camera is PointsFromCam of the model's mount.
#pragma once

#include <map>
#include <optional>
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
  std::map<int, Eigen::Vector2d> candidates_px;  // unconfirmed (session_pose.cc): used from the latest sample only
  // The sample's camera when it is known better than the nominal model's (bundled_cameras.h): used as
  // it is, never resected.
  std::optional<Rigid3> base_from_cam;
};

struct DotPredictionOptions {
  // Single-ray dots: the depth range of at least this many triangulated dots of their sample, widened
  // by this fraction at each end, projected as a segment whose ends lie on the gate of this chi-square.
  int min_depth_neighbours = 3;
  double depth_margin_fraction = 0.1;
  double segment_gate_chi2 = 13.8;      // tracking::PredictedMatchOptions::gate_chi2
  // Predictions outside the image by more than this are left out; those just outside still check a
  // tracked dot that jumped onto another blob as its own left the view.
  double image_margin_px = 1000;
  // The session names a dot only by a gate at most this long (std along its longest axis); a detection
  // alone in a longer gate, up to the second bound, becomes a candidate: with the next settled pose it
  // gives the dot a second ray and a short gate, which then names it or not.
  double max_gate_sigma_px = 4;
  // The nominal model's error per ray, in pixels, beside the pixel noise in every triangulation: a
  // nominal model's rays from two poses miss each other by about this much, which two close rays turn
  // into a large error in depth.
  double ray_model_sigma_px = 1.0;
  double max_candidate_gate_sigma_px = 40;
  // Each sample's camera is resected on the triangulated dots (dot_prediction.cc, SampleCameras) in
  // this many rounds, from at least this many of its dots seen in three samples or more; the dots
  // farther than this (or three times the median) from the resected projection are left out of it.
  int sample_correction_rounds = 2;
  int min_sample_correction_dots = 8;
  double resection_inlier_px = 3.0;
  // A resection is kept only when at least this share of the frame's dots lie within that distance.
  double min_resection_agreeing_fraction = 0.7;
  // The new frame's camera is resected too, on the dots of `current_px` that have points.
  bool resect_new_frame = true;
};

struct DotPredictionReport {
  // In front of the camera and in the image. A dot whose point rests on a candidate also has the segment
  // of its one sample ray, which only competes (names = false); every other dot has one gate.
  std::vector<tracking::PredictedDot> dots;
  // Where the nominal model puts each dot of `current_px` with a point (triangulated from the samples,
  // else from its sample ray and its ray in the new frame): the anchors of the correction of the raw
  // predictions, which a segment's middle cannot be.
  std::map<int, Eigen::Vector2d> anchor_px;
  int triangulated = 0;   // known dots with two rays or more (a candidate's included)
  int on_candidates = 0;  // of them, those whose second ray is a candidate
  int single_ray = 0;     // known dots predicted from one ray, over the scene's depth range
  int not_predicted = 0;  // known dots without a usable prediction (behind, outside, no depth)
};

// The building blocks, shared with the search for dots seen in few samples (seen_once.h).
struct Ray {
  Eigen::Vector3d origin;     // camera centre, base frame
  Eigen::Vector3d direction;  // unit, base frame
};

// A dot's 3-D estimate in the base frame.
struct Point {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
};

// The ray through a pixel of a camera at `base_from_cam`.
Ray RayOf(const PredictionModel& m, const Rigid3& base_from_cam, const Eigen::Vector2d& uv);

// Weighted linear least squares over the rays (each weighted by its lateral std at its depth: pixel
// noise and `ray_model_sigma_px`, one reweighting); false when they fix no point in front of them.
bool Triangulate(const PredictionModel& m, double ray_model_sigma_px, const std::vector<Ray>& rays, Point* out);

// The projection of a point with its covariance, plus the frame's pixel noise, as a gate of dot `id`.
bool ProjectPrediction(const PredictionModel& m, const Rigid3& cam_from_base, const Point& x, int id,
                       tracking::PredictedDot* out);

// Every sample's camera in the base frame: a given one (ViewedSample::base_from_cam) as it is; else the
// first (the gauge) at its nominal pose, the others resected on the dots triangulated from all of them
// (DotPredictionOptions::sample_correction_rounds).
std::vector<Rigid3> SampleCameras(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                  const DotPredictionOptions& options);

// Predictions of every dot of `samples` in a frame taken at `joints_rad`, where the dots `current_px`
// are already known (may be empty).
DotPredictionReport PredictDots(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                const Eigen::VectorXd& joints_rad, const std::map<int, Eigen::Vector2d>& current_px,
                                const DotPredictionOptions& options);

}  // namespace selfcal::acquisition
