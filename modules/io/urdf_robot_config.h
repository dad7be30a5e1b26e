// A robot config that names a URDF (docs/urdf.md) instead of holding a DH table:
//
//   name: ur5e                                  # optional; the URDF's robot name by default
//   source: "..."                               # optional
//   urdf_file: ../../test/data/urdf/ur5e.urdf   # relative to this file's directory
//   base_link: base_link
//   tip_link: tool0                             # the flange
//   camera_link: camera_optical_frame           # optional: the camera's optical frame, fixed below tip_link
//   flange_from_cam: {xyz_mm: [...], rpy_deg: [...]}   # required exactly when camera_link is absent
//
// The chain is converted by urdf::LoadUrdfRobot (modified DH + Hayati beta, checked against KDL).
#pragma once

#include <string>

#include "io/robot_config.h"
#include "io/yaml_schema.h"

namespace selfcal::io {

// True when the map names `urdf_file`.
bool NamesUrdf(const yaml::YamlNode& node);

// Reads the keys above from `map` (the document root of file `problems->file()`) into out->model; every
// problem, the URDF's included, goes to `problems`.
void ParseUrdfRobotConfig(MapReader* map, Problems* problems, CalibratedModel* out);

// The robot config as a session records it: the file's text for a DH config, and for a config naming a
// URDF the converted model in exact form (RobotModelYaml, kExact) with a comment naming the URDF, so that
// the session is readable without the URDF beside it.
Result<std::string> RobotConfigTextForSession(const std::string& path);

}  // namespace selfcal::io
