// Module observations (ARCHITECTURE.md): ObservationSet (this header; UsesFlangePoses, PointsFromCamAt) and
// known distances; pool_recordings.h: several recordings of one arm pooled, each a scene of its own;
// joint_limits.h: the poses whose recorded joints lie outside the limits, named (kept: the controller's
// reading). Uses kinematics, camera.
//
// What a calibration consumes, independent of where it came from (simulator, session, or a file written
// by another tool; docs/observations-format.md is the file form): the nominal robot, the camera, and per
// pose the joint angles and the pixel of each detected dot, by dot id. Data recorded by a cell that logs
// the controller's flange pose instead of joint angles gives base_from_flange per pose; such a set has no
// kinematic model to identify (ObservationSet::robot has no joints: only the base and camera corrections
// exist, and the calibration solves the hand-eye transform, the intrinsics and the scene).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "kinematics/robot_model.h"

namespace selfcal {

enum class PoseRole { kIdentification, kVerification };
const char* PoseRoleName(PoseRole role);

struct PoseObservation {
  std::string id;                               // unique within the set (e.g. "p07")
  PoseRole role = PoseRole::kIdentification;
  Eigen::VectorXd joints_rad;                   // one per robot joint (none for a flange-pose set)
  std::optional<Rigid3> base_from_flange;       // the controller's flange pose, m and rad (flange-pose sets)
  std::map<int, Eigen::Vector2d> dots_px;       // dot id -> pixel (u right, v down, origin top-left centre)
  // The scene the pose sees (empty: the set's one scene). Poses of different scenes see different points
  // even where their dot ids are the same (a board that moved between recordings): SeparateScenes.
  std::string scene;
};

// A known distance between two dots: the yardstick(s) that fix the metric scale, or held-out checks.
struct KnownDistance {
  int dot_a = -1;
  int dot_b = -1;
  double length_m = 0;
};

// The range of a stated centroid noise, px. Below 1e-6 px the weighted Jacobian (entries ~ f_x / sigma)
// squares beyond what the solvers' normal equations hold without overflow at 1e-150 px, and no camera's
// centroids come near it (0.01 px is excellent; a double pixel coordinate resolves ~1e-13 px).
inline constexpr double kMinPixelNoisePx = 1e-6;
inline constexpr double kMaxPixelNoisePx = 100.0;

struct ObservationSet {
  RobotModel robot;                  // nominal model
  CameraIntrinsics camera;           // fx_px is the nominal / initial value (f_x is estimated)
  // False for a flange-pose set that gave no nominal hand-eye transform (robot.flange_from_cam is then
  // the identity): the calibration starts it from the images and the flange motions.
  bool flange_from_cam_known = true;
  // A flange-pose set's stated pose noise (std per axis of the recorded flange poses); 0: exact poses.
  double flange_translation_sigma_m = 0;
  double flange_rotation_sigma_rad = 0;
  double pixel_noise_px = 0.5;       // expected std of the centroids, for weights and uncertainty
  std::vector<KnownDistance> yardsticks;
  std::vector<KnownDistance> check_distances;  // held out from the solve: verification only
  std::vector<PoseObservation> poses;

  // True when every pose gives base_from_flange (and the robot has no joints): the calibration then
  // estimates the hand-eye transform, the intrinsics and the scene, not kinematics; the scale comes from
  // the flange translations, so yardsticks are checks.
  bool UsesFlangePoses() const;
  // Indices of poses with the given role, in file order.
  std::vector<int> PosesWithRole(PoseRole role) const;
  // Empty when consistent; otherwise every problem, one per line, naming the pose id and dot id
  // (joint count, non-finite values, duplicate pose ids, yardstick dots never seen, flange poses in some
  // poses only, ...).
  std::string Validate() const;
};

// The model of a flange-pose set: no joints, identity base, the nominal hand-eye transform.
RobotModel FlangePoseModel(const Rigid3& flange_from_cam);

// The camera of `pose` in the base frame of `robot` with parameters rho: through the joints, or, for a
// flange-pose set, through the recorded flange pose (kinematics/robot_model.h, BaseFromCamGivenFlange).
Rigid3 BaseFromCamAt(const RobotModel& robot, const Eigen::VectorXd& rho, const PoseObservation& pose);
// The camera of `pose` in the frame of the unknown points (kinematics/robot_model.h, PointsFromCam and
// PointsFromCamGivenFlange): BaseFromCamAt eye-in-hand, the flange from the fixed camera eye-to-hand. Every
// projection or triangulation of the dots goes through it.
Rigid3 PointsFromCamAt(const RobotModel& robot, const Eigen::VectorXd& rho, const PoseObservation& pose);

// Pixels of the dots seen in both poses, matched by id (D6: correspondence by id, never by index).
struct Matches {
  std::vector<int> dot_ids;
  std::vector<Eigen::Vector2d> pixels_a, pixels_b;
};
Matches MatchById(const PoseObservation& a, const PoseObservation& b);

// Dot ids of scene k (k > 0, in the order the scenes first appear among the poses; the first scene keeps its
// ids): k * kSceneDotStride + id.
inline constexpr int kSceneDotStride = 1000000;

// The scene names of the poses in the order they first appear (scene k of SeparateScenes is the k-th); one
// empty name for a set whose poses name none.
std::vector<std::string> SceneNames(const ObservationSet& observations);

// A set whose poses name more than one scene, with the dots of each scene made separate points: scene k's dot
// ids moved by k * kSceneDotStride, and every yardstick and check distance repeated for every scene. A set of
// one scene is returned as it is. *scenes (optional): the scene names in that order.
ObservationSet SeparateScenes(const ObservationSet& observations, std::vector<std::string>* scenes = nullptr);

}  // namespace selfcal
