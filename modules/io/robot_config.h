// Module io (ARCHITECTURE.md): the only file I/O of the core, every reader strict (yaml/yaml_reader.h,
// yaml_schema.h) and every writer atomic (base/atomic_file.h). Its files:
//   robot_config.h, urdf_robot_config.h  robot configs (also one naming a URDF, converted by urdf; LoadRobotConfig:
//                           the model with its source and home_deg) and calibrated models (this header)
//   observations_file.h, trajectory_file.h, hand_eye_file.h, fanuc_tracker_csv.h, report_json.h, targets_file.h
//                           observations (joints or flange poses), trajectories (LoadTrajectoryFileForRobot: a
//                           trajectory for another robot refused naming both), hand-eye results, Fanuc tracker CSV,
//                           JSON files, compensate's targets
//   file_lists.h, image_files.h, pose_files.h, json_pose_file.h, skipped_images_file.h
//                           `selfcal detect`'s inputs: files sorted by the number in their names, grey images of one
//                           size, ROS / ViSP / selfcal pose lists (a folder per pose: PoseFolder; tool poses made
//                           the flange's; rotations made rotations within 1e-4 by transform_yaml.h's MakeRotation),
//                           the images --skip-failed left out
//   dh_config_file.h, static_transform_file.h, camera_info_file.h, ur_kinematics_file.h, robot_origin.h
//                           the exports: a DH table as a robot config, ROS's TransformStamped YAML and launch file,
//                           ROS's camera_info YAML, ur_description's kinematics; how the robot was entered (its DH
//                           convention or URDF names, also `entered_as` in a session's recorded robot)
//   camera_file.h, camera_xml.h, camera_formats.h, opencv_lines.h
//                           camera files (docs/camera-files.md): OpenCV FileStorage (its text checked first by the
//                           strict reader or base/xml_scan.h; key lines found by opencv_lines.h) and ViSP's XML
//                           (read by camera_xml.h, written by ViSP); the OpenCV and ViSP calls sit behind
//                           camera_formats.h in selfcal_io_camera_formats, which `selfcal` loads by dlopen as
//                           libselfcal_camera_formats.so when a camera file first needs it (the target property
//                           SELFCAL_LOAD_CAMERA_FORMATS); every other program links it
// Uses yaml, urdf, planning, observations, kinematics, geometry, base.
//
// Robot description files (config/robots/*.yaml) and calibrated-model files.
//
// A robot config (mm and degrees in the file, SI inside; keys carry their unit, and either unit of a
// pair may be used: `a_mm` or `a_m`, `alpha_deg` or `alpha_rad`):
//
//   name: puma560
//   source: "Corke, Robotics Toolbox for MATLAB, mdl_puma560 (standard DH)"   # optional
//   dh_convention: standard        # standard | modified | modified_hayati
//   joints:                        # one row per joint, base to flange
//     - {a_mm: 0.0, alpha_deg: 90.0, d_mm: 0.0, theta_offset_deg: 0.0, min_deg: -160, max_deg: 160}
//   base_from_link0: {xyz_mm: [0, 0, 0], rpy_deg: [0, 0, 0]}       # optional, identity by default
//   flange_from_cam: {xyz_mm: [40, 0, 60], rpy_deg: [0, 0, 90]}    # required: nominal hand-eye
//   link_n_from_flange: {...}      # optional, modified and modified_hayati only
//   home_deg: [0, 20, -200, 0, 45, 0]  # optional (or home_rad): where `make-trajectory` starts its arc;
//                                  # one value per joint, inside the joint limits
//
// Conventions (kinematics/robot_model.h): standard rows are Rz(q+theta) Tz(d) Tx(a) Rx(alpha);
// modified rows are Rx(alpha) Tx(a) Rz(q+theta) Tz(d); modified_hayati rows add `beta` (optional,
// default 0): Rx(alpha) Tx(a) Ry(beta) Rz(q+theta) Tz(d). `theta_offset` is optional (default 0).
// Transforms and rpy: io/transform_yaml.h. Every problem of the file is reported together (C1-C3).
//
// A calibrated model (SaveCalibratedModel) is a robot config with dh_convention: modified_hayati plus
// `format: selfcal-calibrated-model`, `version: 1`, and the optional keys `fx_px`, `camera`,
// `intrinsics_stddev`, `parameters` and `provenance`; LoadRobotModel reads it too.
// docs/calibrated-model-format.md describes both.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "camera/camera.h"
#include "io/transform_yaml.h"
#include "io/yaml_schema.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

inline constexpr const char* kRobotFormat = "selfcal-robot";
inline constexpr const char* kCalibratedModelFormat = "selfcal-calibrated-model";
inline constexpr int kCalibratedModelVersion = 1;

struct CalibratedModel {
  RobotModel model;            // calibrated (e.g. ApplyParameters(nominal, rho)); SI
  std::string source;          // free text, e.g. which session produced it; optional
  double fx_px = 0;            // identified focal length; 0 = not stored
  // The calibrated camera (every intrinsic, the `camera:` block of an observations file) and the standard
  // deviations of the estimated intrinsics (NaN: held or unknown); not stored when empty / all NaN.
  std::optional<CameraIntrinsics> camera;
  IntrinsicsVector intrinsics_stddev = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
  Eigen::VectorXd parameters;  // rho (SI) in KinematicParameters order; empty = not stored
  std::vector<std::pair<std::string, std::string>> provenance;  // P7: software, hashes, session id ...
  // A robot config's `home_deg` (rad): the joint angles where the camera looks at the scene, from which
  // `selfcal make-trajectory` sweeps its arc (sim/trajectory_generator.h). Empty: the config gives none.
  std::vector<double> home_rad;
};

// Reads a robot config or a calibrated-model file. Errors: ErrorCode::kInvalidInput, naming file, line, key
// and value of every problem.
Result<RobotModel> LoadRobotModel(const std::string& path);

// Parses a robot config (or calibrated-model file) already in memory, e.g. a session's verified copy;
// `name` stands for the file in messages. Same checks and errors as LoadRobotModel.
Result<RobotModel> ParseRobotModelText(const std::string& text, const std::string& name);

// Reads a robot config or a calibrated-model file with what it says beside the model: `source` and
// `home_deg` (CalibratedModel::home_rad). Same checks and errors as LoadRobotModel.
Result<CalibratedModel> LoadRobotConfig(const std::string& path);

// Reads a calibrated-model file (`format: selfcal-calibrated-model` required).
Result<CalibratedModel> LoadCalibratedModel(const std::string& path);

// Writes `calibrated` atomically as YAML in mm / degrees (alpha_deg, a_mm, beta_deg, theta_offset_deg,
// d_mm per joint; transforms as xyz_mm / rpy_deg), with 17 significant digits where needed so that
// reading it back reproduces the forward kinematics to ~1e-15 m. Refuses an invalid model.
Status SaveCalibratedModel(const CalibratedModel& calibrated, const std::string& path);

// Parses a robot description held in `node` (a document root, or the `robot:` block of an observations
// file), recording problems under the key path `name`. The returned model is meaningful only when no
// problem was added. Calibrated-model keys are accepted when the map has
// `format: selfcal-calibrated-model`.
CalibratedModel ParseRobotModel(const yaml::YamlNode& node, const std::string& name, Problems* problems);

// The robot as a YAML block of `indent` spaces (keys name, dh_convention: modified_hayati, joints,
// base_from_link0, link_n_from_flange, flange_from_cam). kExact writes SI values and rotation matrices
// so that ParseRobotModel gives back the identical model bit for bit; kMillimetreDegree is for people.
std::string RobotModelYaml(const RobotModel& model, TransformStyle style, int indent);

}  // namespace selfcal::io
