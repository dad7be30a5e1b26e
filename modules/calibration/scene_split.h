// Did the scene move between the poses of one set? Two recordings copied into one folder, or a board bumped
// halfway through a session, make one set whose points are not where they were for every image. Solved as one
// scene, the bundle's cell error model absorbs the move as a large pose error per image, and the model that
// results predicts held-out poses at the size of the move, not of the cell.
//
// FindSceneSplit looks at each image alone: with the solved model's camera held at the image's joints, the
// rigid move of the solved points that best explains that image's dots (scene_shift.h, SceneShiftOfPoses on
// one pose). Two images are as far apart as the RMS (px) each gains with the other's move instead of its own
// (a direction one image cannot see, e.g. a flat board's tilt against its shift, costs nothing), and the
// images are split in two by two medoids (every pair tried). Each image's move also carries the model's
// error at its configuration, so the groups' distance does not decide. What decides is whether one move per
// group explains the residual: each group's move fitted to all its images at once, cameras held, which
// errors that change from configuration to configuration follow only in part. The split is named when the
// RMS with a move per group is at most 1 / kSplitRmsRatio of the RMS with the solved points (on the Panda
// recordings a still scene stays within 5 %), the groups' places differ by at least kSceneMovedMinM or
// kSceneMovedMinRad, and each group holds at least kSplitMinPoses identification poses.
//
// A smooth model error can pass that screen too (two groups of nearby configurations each take their mean
// error as a move), so Calibrate (calibrate.h) solves the set again with a scene each (observation_set.h
// SeparateScenes) and takes that solve only when its scenes' points lie apart (scene_moves.h) and it predicts
// held-out poses kSplitHeldOutGain times better: a moved scene is the one-scene solve's largest error, a model
// error is not undone by a second scene.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

inline constexpr double kSplitRmsRatio = 1.5;
inline constexpr double kSplitHeldOutGain = 3.0;
inline constexpr double kSceneMovedMinRad = 0.05 * 3.14159265358979323846 / 180;
inline constexpr int kSplitMinPoses = 3;

struct SceneSplit {
  // The images' moves computed and compared (false: fewer than 2 x kSplitMinPoses images with points, or a
  // solve with non-finite parameters or points; then nothing else is set).
  bool checked = false;
  bool found = false;    // two groups, as above
  int images = 0;        // images whose move was computed
  // The two groups' pose ids, in the order of obs.poses (found only); the first group holds obs.poses' first
  // pose with a move.
  std::vector<std::string> first_poses, second_poses;
  double separation_px = 0;              // distance of the two medoids
  double scatter_first_px = 0, scatter_second_px = 0;  // each group's median distance from its medoid
  // The RMS per coordinate of the images' dots with the solved points in one place (the solve's) and with one
  // move of them per group.
  double rms_one_place_px = 0, rms_two_places_px = 0;
  // The move from the first group's place of the points to the second's (each group's move of the solved
  // points): the translation of the points' centroid and the rotation.
  double translation_m = 0, rotation_rad = 0;
  // Set by Calibrate: whether the result is the solve with a scene each, and why (not).
  bool applied = false;
  std::string decision;
  double one_scene_heldout_px = 0, split_heldout_px = 0;  // the two solves' held-out RMS (0: none)
};

// Over every pose of `obs` (one scene; any role) with at least 4 dots among `points` (id -> position in the
// points' frame, the bundle's dots_in_base), seen by `camera` from `robot` with parameters `rho`.
SceneSplit FindSceneSplit(const ObservationSet& obs, const RobotModel& robot, const Eigen::VectorXd& rho,
                          const CameraIntrinsics& camera, const std::map<int, Eigen::Vector3d>& points);

// `obs` with each pose of the split's groups in a scene of its own ("scene 1": first_poses, "scene 2":
// second_poses; a pose in neither, e.g. one without points, stays in scene 1), then SeparateScenes.
ObservationSet WithSplitScenes(const ObservationSet& obs, const SceneSplit& split);

}  // namespace selfcal::calibration
