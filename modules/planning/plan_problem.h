// What the planner is given (issue 4): the robot's nominal model, the camera, where the dots roughly are,
// and the constraints every measurement configuration must satisfy. Shared by the planner
// (planning/planner.h), the plan check (planning/plan_check.h) and the observability report.
//
// Frames and units: dots and box in the frame of the points (m): the robot base frame in eye-in-hand, the
// flange frame in eye-to-hand (robot.mount; every view is then PointsFromCam, the fixed camera seen from the
// flange, and the constraints apply to it); joint angles in rad; pixels as in
// camera/camera.h; the camera's f_x is the nominal one (the planner never knows the true f_x).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "kinematics/robot_model.h"

namespace selfcal::planning {

// Where the dots are, roughly. Either a box (the planner spreads num_dots seeded points inside it to stand
// for the dots, and requires the box's 8 corners in every image) or rough dot positions (every one of them
// required in every image, by the planner's barrier and by the check).
struct Scene {
  std::vector<Eigen::Vector3d> dots_in_base;    // stand-ins for the dots (Fisher information, yardstick)
  std::vector<Eigen::Vector3d> extent_in_base;  // points every image must contain with the margin

  static Scene FromBox(const Eigen::Vector3d& center_m, const Eigen::Vector3d& size_m, int num_dots, uint64_t seed);
  static Scene FromDots(const std::vector<Eigen::Vector3d>& dots_in_base);
  // The mean of the extent points (eye-to-hand: the plate's centre, PlateViewingAngle).
  Eigen::Vector3d Centre() const;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

struct PlanConstraints {
  double joint_margin_rad = DegToRad(5.0);  // inside the joint limits by at least this
  double image_margin_px = 10.0;            // every scene point this far inside every image
  double min_depth_m = 0.25;                // every scene point at a depth in [min, max] in every view
  double max_depth_m = 2.0;
  // Camera centres of any two poses at least this far apart (duplicates and near-duplicates, C7; the factor
  // method also needs a baseline: pure rotation makes t unobservable, G3).
  double min_spread_m = 0.02;
  // f_x observable by the identification poses as a set, which is what the default method (the kinematic
  // bundle adjustment over every image) needs: the Cramer-Rao standard deviation of f_x from the bundle's
  // Fisher information (planning/fisher_design.h, dots unknown) at pixel_noise_px, relative to the
  // nominal f_x, at most this. The shipped arc: 1.1 px of 1000 (0.0011); its bundle error over 5 seeds
  // stays within 2 sigma (docs/planning.md).
  double max_fx_stddev_rel = 0.005;
  double pixel_noise_px = 0.2;  // the noise of that bound
  // The paper method (Method::kPaper) recovers f_x from every pair (reference, i): for every
  // identification pose i, the sine of the angle between one optical axis and the plane through the other
  // axis and the second camera centre, at least this. Near zero the axes (nearly) intersect and f_x is
  // unobservable from the pair (../shared/DESIGN.md section 4); the two-view estimator's own threshold is 0.05
  // (twoview::TwoViewOptions::focal_observability_min), 0.08 keeps a margin. 0 (the default): not a
  // constraint (the bundle does not need it); the check reports the pairs below 0.08 as a figure.
  double min_axis_sine = 0.0;
  // Image motion per move, what the session needs to keep the dots' identities by tracking through the
  // move: the median displacement (px) of the scene's dots seen at both ends of each move between
  // consecutive poses, at most this. The shipped PUMA arc's largest is 41 px (docs/planning.md).
  double max_image_motion_px = 100.0;
  // Largest change of any joint between consecutive poses (the order the robot visits them).
  double max_joint_travel_rad = DegToRad(90.0);
  // Eye-to-hand (robot.mount): the plate carried by the flange faces the fixed camera, its normal (the
  // flange's z axis) within this angle of the direction from the scene's centre to the camera
  // (PlateViewingAngle, view_geometry.h): past it the dots are seen too obliquely to be detected.
  double max_viewing_angle_rad = DegToRad(55.0);
  // Fewer identification poses are refused (the paper's 6m > n; the rank check decides the rest).
  int min_identification_poses = 6;
  // Insufficient excitation (C7): refused when the identification poses identify fewer parameters than
  // generic poses of the robot, or the column-normalised identification Jacobian's condition number
  // exceeds this.
  double max_condition_number = 1e4;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

// What a plan was planned and checked with: the plan file records it (docs/trajectory-format.md
// `planned_for`), so that `selfcal plan --check` and `selfcal run` check the same scene and camera.
struct PlannedFor {
  CameraIntrinsics camera;
  Scene scene;
  PlanConstraints constraints;
  // Where the camera is: eye-in-hand (the scene in the base frame), or eye-to-hand (the scene on the plate
  // in the flange frame, seen by the fixed camera base_from_cam). The check applies it to the robot config.
  CameraMount configuration = CameraMount::kEyeInHand;
  Rigid3 base_from_cam = Rigid3();  // eye-to-hand only: the nominal fixed camera the plan was made for
};

struct PlanningProblem {
  RobotModel robot;        // nominal (zero base and camera corrections are used)
  CameraIntrinsics camera; // nominal intrinsics
  Scene scene;
  int num_identification_poses = 15;  // the first poses of a plan; the rest verify (the paper: 15 + 10)
  PlanConstraints constraints;
  std::string Validate() const;
};

}  // namespace selfcal::planning
