// Where the scenes of a pooled set lie against each other: recordings of one arm calibrated together with
// a scene each (observations/pool_recordings.h, or poses that name their `scene:`) whose points share ids
// (the same board, dot for dot). After the solve every scene's points are in the robot's base frame, so a
// board that moved between recordings shows as the displacement of its points from the first scene's, and
// a rigid transform fitted to them (Umeyama, no scale) gives the move's rotation and what is not rigid.
//
// A scene is said to have moved when its points' RMS displacement is over kSceneMovedFactor times the
// rigid fit's RMS residual and over kSceneMovedMinM: the residual is the points' own scatter (noise and
// calibration error together), which a move that did not happen would not exceed.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "observations/observation_set.h"

namespace selfcal::calibration {

inline constexpr double kSceneMovedFactor = 3.0;
inline constexpr double kSceneMovedMinM = 0.5e-3;

struct SceneMove {
  std::string scene, relative_to;   // scene names (pose.scene), the second the first scene of the set
  int shared_points = 0;            // points of both scenes (same id)
  double displacement_rms_m = 0;    // |p_scene - p_first| over the shared points
  double displacement_max_m = 0;
  double rotation_rad = 0;          // of the rigid transform from the first scene's points to these
  double rigid_fit_rms_m = 0;       // residual of that transform
  bool moved = false;
};

// One entry per scene after the first that shares at least three points with it; empty for a set of one
// scene. `dots_in_base` keyed as SeparateScenes numbers them (scene k: k * kSceneDotStride + id).
std::vector<SceneMove> SceneMovesOf(const ObservationSet& observations, const std::map<int, Eigen::Vector3d>& dots_in_base);

}  // namespace selfcal::calibration
