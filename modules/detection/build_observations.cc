#include <sstream>

#include "detection/detect_points.h"

namespace selfcal::detection {

Result<ObservationSet> BuildObservationSet(const std::vector<std::string>& pose_ids,
                                           const std::vector<ImagePoints>& points,
                                           const std::vector<ImageRobotPose>& robot_poses,
                                           const ObservationSetup& setup) {
  SELFCAL_CHECK(pose_ids.size() == points.size() && points.size() == robot_poses.size(),
                "BuildObservationSet: " << pose_ids.size() << " ids, " << points.size() << " point sets, "
                                        << robot_poses.size() << " robot poses");
  size_t flange_poses = 0;
  for (const ImageRobotPose& p : robot_poses) flange_poses += p.base_from_flange.has_value() ? 1 : 0;
  if (flange_poses != 0 && flange_poses != robot_poses.size()) {
    return Status::Error(ErrorCode::kInvalidInput, std::to_string(flange_poses) + " of " +
                                                       std::to_string(robot_poses.size()) +
                                                       " images have flange poses and the others joint angles: give "
                                                       "one or the other for every image");
  }
  const bool flange_set = flange_poses != 0;
  ObservationSet set;
  set.robot = flange_set ? FlangePoseModel(setup.flange_from_cam.value_or(Rigid3())) : setup.robot;
  set.flange_from_cam_known = !flange_set || setup.flange_from_cam.has_value();
  if (setup.mount == CameraMount::kEyeToHand) {
    SELFCAL_CHECK(!setup.flange_from_cam.has_value(), "BuildObservationSet: eye-to-hand takes base_from_cam");
    set.robot.mount = CameraMount::kEyeToHand;
    set.robot.base_from_cam = setup.base_from_cam.value_or(Rigid3());
    set.flange_from_cam_known = setup.base_from_cam.has_value();
  }
  set.camera = setup.camera;
  set.pixel_noise_px = setup.pixel_noise_px;
  set.flange_translation_sigma_m = setup.flange_translation_sigma_m;
  set.flange_rotation_sigma_rad = setup.flange_rotation_sigma_rad;
  set.yardsticks = setup.yardsticks;
  set.check_distances = setup.check_distances;
  std::string failed;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].ok || points[i].points_px.empty()) {
      failed += "\n  - " + pose_ids[i] + ": " + (points[i].message.empty() ? "no point found" : points[i].message);
      continue;
    }
    PoseObservation pose;
    pose.id = pose_ids[i];
    pose.role = robot_poses[i].role;
    if (flange_set) {
      pose.base_from_flange = robot_poses[i].base_from_flange;
    } else {
      pose.joints_rad = robot_poses[i].joints_rad;
    }
    pose.dots_px = points[i].points_px;
    set.poses.push_back(std::move(pose));
  }
  if (!failed.empty() && !setup.skip_failed) {
    return Status::Error(ErrorCode::kDegenerateData,
                         "no points in " + std::to_string(points.size() - set.poses.size()) + " of " +
                             std::to_string(points.size()) + " images (leave them out with --skip-failed):" + failed);
  }
  if (set.poses.empty()) return Status::Error(ErrorCode::kDegenerateData, "no image gave any point:" + failed);
  if (const std::string problems = set.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "the observations are not consistent:\n" + problems);
  }
  return set;
}

}  // namespace selfcal::detection
