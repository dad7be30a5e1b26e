// How the nominal robot was entered, for the exports that speak the user's language (docs/urdf.md,
// docs/calibrated-model-format.md): the DH convention of a robot config, or the joint and link names of a
// URDF. Read from the robot config, from an observations file's robot (robot_file or the robot block), or
// from a session's recorded robot.yaml, where a URDF robot is recorded as its converted model with
//
//   entered_as: {base_link: "base_link", tip_link: "tool0", camera_link: "camera_optical_frame",
//                joint_names: ["joint1", ...], urdf_file: "/abs/path/robot.urdf"}
//
// (accepted in modified_hayati configs, the form selfcal writes; no part of the kinematics).
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "io/yaml_schema.h"

namespace selfcal::io {

struct RobotOrigin {
  std::string dh_convention;             // "standard", "modified", "modified_hayati"; empty for a URDF / unknown
  std::vector<std::string> joint_names;  // the URDF's movable joints, base to tip; empty otherwise
  std::string base_link, tip_link, camera_link;  // the URDF's links; empty otherwise
  // The URDF file itself (resolved beside the config) when read from a config naming it, or as a session
  // recorded it (absolute); empty otherwise. calibrated.urdf is this file with the calibrated origins when
  // it is still there and still converts to the calibrated arm (urdf/urdf_calibrated.h).
  std::string urdf_file;
  // A DH config's optional `name`, `link` and `max_velocity_deg_s` of every joint row (all rows or none):
  // calibrated.urdf's joint and link names and <limit velocity> (rad/s); empty when not given.
  std::vector<std::string> config_joint_names, config_link_names;
  std::vector<double> max_velocity_rad_s;

  bool FromUrdf() const { return !joint_names.empty(); }
};

// `file` as named in the config at `config_path`: absolute as is, else relative to the config's directory.
std::string ResolveBesideConfig(const std::string& file, const std::string& config_path);

// The `entered_as` map of `root` into *origin (nothing when absent); problems to root->problems().
bool ReadEnteredAs(MapReader* root, RobotOrigin* origin);

// The `entered_as: {...}` line for a URDF robot (empty otherwise).
std::string EnteredAsYaml(const RobotOrigin& origin);

// Of a robot config file (a URDF-naming config: its names, the URDF read for the joint names) or its
// text already in memory (`path` standing for the file and resolving a relative urdf_file).
Result<RobotOrigin> RobotOriginOfConfig(const std::string& path);
Result<RobotOrigin> RobotOriginOfConfigText(const std::string& text, const std::string& path);

// Of an observations file's robot: its robot_file's origin, or its robot block's; also of the file's
// document already parsed (robot_file resolved beside doc.path), so that a reader parses it once.
Result<RobotOrigin> RobotOriginOfObservations(const std::string& path);
Result<RobotOrigin> RobotOriginOfObservations(const yaml::YamlDocument& doc);

}  // namespace selfcal::io
