// A synthetic eye-to-hand cell with known truth, for the bundle and calibration tests (no renderer: the
// dots are projected): a camera fixed about 1 m from the workspace looks at dots on a plate carried by the
// flange (a few raised off the plate, so the points are not coplanar), over joint poses of varied flange
// orientation that keep every dot in view. The hidden arm differs from the nominal one on the parameters
// its poses identify (the eye-in-hand relative-pose analysis of the same poses: the two mounts fix mirror
// sets, base and joint 1 by the camera correction, the tail by the points); the hidden camera differs from
// the nominal base_from_cam; one yardstick joins two plate dots.
#pragma once

#include <cstdint>
#include <vector>

#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::testing {

// Franka Emika Panda, modified DH from config/robots/panda.yaml (flange 107 mm along z of link 7).
RobotModel Panda();

struct EyeToHandOptions {
  int num_poses = 25;         // identification
  int num_verification = 0;  // more poses, held out (PoseRole::kVerification), and a check distance
  int num_dots = 15;         // 5 or fewer: a flat 100 mm square tag, its corners and centre (an AprilTag's)
  double noise_px = 0;
  double camera_distance_m = 1.0;
  double length_error_m = 0.5e-3;   // hidden errors: uniform in +-(0.2 .. 1) x these
  double angle_error_rad = 0.05 * kPi / 180;
  double cam_length_error_m = 5e-3;  // hidden error of base_from_cam, per entry
  double cam_angle_error_rad = 5e-3;
  double fx_relative_error = 0.01;   // of the true f_x against the nominal
  // Flange-pose set: the true flange poses recorded, no joints (ObservationSet::UsesFlangePoses).
  bool flange_poses = false;
  uint64_t seed = 1;        // the world: hidden errors, poses, dots
  uint64_t noise_seed = 1;  // the pixel noise
};

// The shape of ViSP's eye-to-hand data: 8 recorded flange poses (no joints), one tag's 4 corners and centre,
// the camera 0.5 m away.
EyeToHandOptions TagFlangePoseOptions(double noise_px, uint64_t seed);

struct EyeToHandWorld {
  ObservationSet observations;  // nominal robot (mount eye_to_hand), nominal camera, poses, yardstick
  Eigen::VectorXd rho_true;     // on observations.robot
  std::vector<int> perturbed_indices;  // the rho entries the truth moved, ascending
  CameraIntrinsics camera_true;
  std::vector<Eigen::Vector3d> dots_in_flange;  // by dot id
  Rigid3 base_from_cam_true;
  std::vector<Rigid3> base_from_flange_true;    // per pose
};

// `nominal`: a robot of test_robots.h (or Panda()); its mount and base_from_cam are set here. Fails the
// calling test (non-fatally) when poses cannot be found.
EyeToHandWorld MakeEyeToHandWorld(const RobotModel& nominal, const EyeToHandOptions& options);

// The same world's pixels again with another noise draw.
ObservationSet ReobserveEyeToHand(const EyeToHandWorld& world, double noise_px, uint64_t noise_seed);

}  // namespace selfcal::testing
