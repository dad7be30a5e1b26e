// A smooth measurement trajectory around a scene: the paper's "initial" trajectory (section 4.2: "the
// initial measurement samples were generated along a smooth path in the workspace of the robot").
// The camera centre sweeps an arc around a target point, looking at it with a slowly wandering aim point
// and roll so that no two optical axes intersect (f_x would be unobservable from such a pair, ../shared/DESIGN.md
// section 4). Joint angles come from inverse kinematics of the nominal model, continued pose to pose.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"

namespace selfcal::sim {

struct ArcTrajectoryOptions {
  int num_poses = 25;
  // The camera looks at a target distance_m ahead of where it is at these joint angles (the PUMA 560's
  // forearm-down, wrist-tilted pose by default); the arc sweeps around that target.
  std::vector<double> home_joints_deg = {0.0, 20.0, -200.0, 0.0, 45.0, 0.0};
  double distance_m = 0.65;          // camera centre to target, mean
  double distance_swing_m = 0.08;
  double azimuth_start_deg = -35.0;  // viewing direction about the vertical through the target, from home
  double azimuth_end_deg = 35.0;
  double elevation_swing_deg = 10.0; // viewing direction's elevation about home's
  double aim_wander_m = 0.04;        // radius of the aim point's circle around the target
  double roll_swing_deg = 25.0;
  double joint_margin_rad = DegToRad(5.0);
};

struct GeneratedTrajectory {
  bool ok = false;
  std::string message;
  std::vector<Eigen::VectorXd> joints;  // rad
};

GeneratedTrajectory MakeArcTrajectory(const RobotModel& nominal, const ArcTrajectoryOptions& options);

// Eye-to-hand (nominal.mount): a smooth path of the flange in front of the fixed camera (the nominal
// RobotModel::base_from_cam). The plate's centre (plate_standoff_m along the flange's z) wanders a Lissajous
// path around where it is at home, the plate's normal tilts about the direction to the camera and the flange
// rolls about it, so that the plate stays in view, facing the camera, while every wrist joint moves. Joint
// angles from the flange's inverse kinematics on the nominal model, continued pose to pose.
struct EyeToHandTrajectoryOptions {
  int num_poses = 25;
  std::vector<double> home_joints_deg;  // where the plate faces the camera (sim::DefaultFixedCamera's home)
  double plate_standoff_m = 0.03;
  Eigen::Vector3d wander_m = Eigen::Vector3d(0.08, 0.06, 0.05);  // half-amplitudes in the camera's x, y, z
  double tilt_deg = 22.0;       // plate normal away from the direction to the camera, at most
  double roll_swing_deg = 45.0;
  double joint_margin_rad = DegToRad(5.0);
};
GeneratedTrajectory MakeEyeToHandTrajectory(const RobotModel& nominal, const EyeToHandTrajectoryOptions& options);

}  // namespace selfcal::sim
