// --configuration eye_in_hand|eye_to_hand of `plan`, `run`, `simulate` and `detect` (kinematics/robot_model.h,
// CameraMount): where the camera is. Eye-in-hand (the default) is the camera on the flange looking at dots
// fixed in the base frame; eye-to-hand a camera fixed in the base frame looking at dots on a plate the flange
// carries. The simulated eye-to-hand cell's nominal fixed camera is sim::DefaultFixedCamera at the robot
// config's home_deg; a real camera's is setup.json's `base_from_cam` (docs/session-format.md).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "base/status.h"
#include "kinematics/robot_model.h"

namespace selfcal::app {

// Adds --configuration (checked to be one of the two names) to `cmd`.
void AddConfigurationOption(CLI::App* cmd, std::string* configuration);

// kInvalidInput for a name that is not eye_in_hand or eye_to_hand.
Result<CameraMount> ParseConfiguration(const std::string& name);

// `robot` (the config at `robot_path`) in the simulated cell of `mount`: unchanged in eye-in-hand; in
// eye-to-hand its mount set and base_from_cam the simulated cell's fixed camera (sim::DefaultFixedCamera at
// the config's home_deg; kInvalidInput when the config has none).
Result<RobotModel> RobotInSimulatedCell(const RobotModel& robot, const std::string& robot_path, CameraMount mount);

// The eye-to-hand start trajectory of `robot` (in its eye-to-hand cell): sim::MakeEyeToHandTrajectory from
// the config's home_deg, `poses` poses. kDegenerateData when the arm cannot follow it.
Result<std::vector<Eigen::VectorXd>> EyeToHandStart(const RobotModel& robot, const std::string& robot_path, int poses);

// `run --resume`: kInvalidInput, before anything is opened or written, when the session at `session` was
// recorded in another configuration than `requested` (its session.json), naming the session and both. A
// directory without a readable manifest is left to the resume's own checks.
Status CheckResumeConfiguration(const std::string& session, CameraMount requested);

}  // namespace selfcal::app
