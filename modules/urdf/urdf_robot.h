// Module urdf (ARCHITECTURE.md; docs/urdf.md): LoadUrdfRobot (this header), checked against KDL's chain of
// the same URDF (kdl_chain.h builds it from urdfdom's model; kdl_parser's tree only in the tests) to 1e-9 at
// seeded random joints; urdf_writer.h: WriteUrdf, a model as a URDF, checked with KDL before it is written;
// urdf_calibrated.h: CalibratedUserUrdf, the user's own URDF with only the joint origins changed, checked the
// same way; urdf_parse.h: the text scanned by base/xml_scan.h, then tinyxml for a syntax error's line, then
// urdfdom with its console_bridge messages captured and placed at the line of the element they name.
// Uses kinematics, geometry, base; urdfdom, tinyxml, console_bridge and KDL private.
//
// A URDF robot as selfcal's nominal RobotModel (docs/urdf.md).
//
// The chain from `base_link` to `tip_link` of a URDF read with urdfdom becomes the modified-DH + Hayati
// model of kinematics/robot_model.h: every movable joint's axis as a line in the base frame at q = 0, the
// common normal between consecutive axes (Hayati's beta where they are parallel), fixed joints folded into
// the neighbouring transforms; base_link is the model's base, tip_link its flange, and `camera_link`, when
// named, a link rigidly attached below tip_link whose frame is the camera's optical frame (flange_from_cam).
// Only revolute joints with limits are taken (their limits and names kept); prismatic, continuous, planar
// and floating joints on the chain are refused by name. The converted model's forward kinematics is then
// checked against KDL's (the KDL chain built from urdfdom's reading of the same URDF, kdl_chain.h) at seeded random joint values
// within the limits, and refused with the worst pose when they differ by more than 1e-9 m / 1e-9 rad.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::urdf {

struct UrdfChainSpec {
  std::string base_link;
  std::string tip_link;
  std::string camera_link;  // empty: flange_from_cam is given by the caller
};

struct FkCheckOptions {
  int samples = 200;
  std::uint64_t seed = 1;
  double tolerance_m = 1e-9;
  double tolerance_rad = 1e-9;
};

// The worst difference found between the model and KDL, and where.
struct FkCheck {
  int samples = 0;
  int worst_sample = -1;    // 0-based; -1 when no sample
  Eigen::VectorXd worst_q;  // rad
  double worst_position_m = 0;
  double worst_rotation_rad = 0;
};

struct UrdfRobot {
  RobotModel model;
  std::vector<std::string> joint_names;  // the chain's movable joints, base to tip
  FkCheck check;                         // the KDL comparison it passed
};

// Reads the URDF at `path` (or already in memory as `text`, `name` standing for the file in messages)
// and converts the chain. `flange_from_cam` is used when spec.camera_link is empty (required then).
// Errors: kInvalidInput naming the file, link or joint; kInvalidInput naming the worst pose when the KDL
// check fails.
Result<UrdfRobot> LoadUrdfRobot(const std::string& path, const UrdfChainSpec& spec,
                                const std::optional<Rigid3>& flange_from_cam, const FkCheckOptions& check = {});
Result<UrdfRobot> ParseUrdfRobot(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                                 const std::optional<Rigid3>& flange_from_cam, const FkCheckOptions& check = {});

// KDL's forward kinematics of the chain base_link -> tip_link of the URDF `text` at each joint vector of
// `joints` (rad, one per movable joint of the chain): base_from_tip. For the check and its tests.
Result<std::vector<Rigid3>> KdlChainPoses(const std::string& text, const std::string& name,
                                          const std::string& base_link, const std::string& tip_link,
                                          const std::vector<Eigen::VectorXd>& joints);

// Seeded random joint vectors, uniform within the model's limits.
std::vector<Eigen::VectorXd> RandomJointsWithinLimits(const RobotModel& model, int count, std::uint64_t seed);

}  // namespace selfcal::urdf
