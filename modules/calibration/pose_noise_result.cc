#include "calibration/pose_noise_result.h"

#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <utility>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::calibration {

namespace {

// The robot with the solve's hand-eye transform in place of the set's (zero corrections on it).
RobotModel RobotOf(const ObservationSet& obs, const bundle::PoseNoiseReport& solve) {
  RobotModel robot = obs.robot;
  if (robot.mount == CameraMount::kEyeToHand) {
    robot.base_from_cam = solve.base_from_cam;
  } else {
    robot.flange_from_cam = solve.flange_from_cam;
  }
  return robot;
}

ExcludedObservations ExcludedOf(const bundle::PoseNoiseReport& solve) {
  ExcludedObservations excluded;
  for (const auto& [pose, dot] : solve.removed) excluded.insert({pose, dot});
  return excluded;
}

// A fold's pose-noise solve on `train`, started from the whole one, and its prediction of the fold.
FoldFit FitPoseNoise(const ObservationSet& train, const bundle::PoseNoiseReport& full, const bundle::PoseNoiseOptions& noise) {
  FoldFit fit;
  const bool eye_to_hand = train.robot.mount == CameraMount::kEyeToHand;
  const bundle::PoseNoiseReport solve =
      bundle::RunPoseNoiseBundle(train, eye_to_hand ? full.base_from_cam : full.flange_from_cam, full.dots, noise);
  fit.outcome = solve.ok ? bundle::Outcome::kConverged : bundle::Outcome::kFailure;
  fit.message = solve.message;
  if (solve.ok) fit.heldout = PoseNoiseHeldOut(train, solve, noise);
  return fit;
}

}  // namespace

PredictionModel PoseNoisePredictionModel(const ObservationSet& obs, const bundle::PoseNoiseReport& solve,
                                         const bundle::PoseNoiseOptions& noise) {
  PredictionModel model;
  model.robot = RobotOf(obs, solve);
  model.rho = KinematicParameters::Nominal(model.robot);
  model.camera = WithIntrinsics(obs.camera, solve.intrinsics);
  model.intrinsics_estimated = solve.intrinsics_estimated;
  const int cam = KinematicParameters(model.robot.num_joints()).CamOffset();
  for (int k = 0; k < 6; ++k) model.free_indices.push_back(cam + k);
  model.covariance = solve.covariance;  // empty when unavailable: the parameters taken as exact
  model.pose_translation_m = noise.translation_sigma_m;
  model.pose_rotation_rad = noise.rotation_sigma_rad;
  model.pose_error_at_flange = true;
  return model;
}

HeldOutReprojection PoseNoiseHeldOut(const ObservationSet& obs, const bundle::PoseNoiseReport& solve,
                                     const bundle::PoseNoiseOptions& noise) {
  HeldOutReprojection heldout = HeldOutReprojectionOf(obs, PoseNoisePredictionModel(obs, solve, noise), solve.dots,
                                                      ExcludedOf(solve), obs.pixel_noise_px, 0);
  heldout.noise_source = "the stated pixel noise, with each image's flange pose noise as modelled by the pose-noise solve";
  if (heldout.ok && solve.covariance.size() == 0) {
    heldout.message = "prediction uncertainty of the hand-eye transform and intrinsics left out: the pose-noise solve "
                      "gave no covariance";
  }
  return heldout;
}

CrossValidationReport CrossValidatePoseNoise(const ObservationSet& obs, const bundle::PoseNoiseReport& full,
                                             const bundle::PoseNoiseOptions& noise, int folds, std::uint64_t seed) {
  ObservationSet start = obs;  // the folds start at the whole solve's intrinsics
  start.camera = WithIntrinsics(obs.camera, full.intrinsics);
  CrossValidationReport report = CrossValidateWith(
      start, folds, seed, [&](const ObservationSet& train) { return FitPoseNoise(train, full, noise); });
  if (!report.ran) return report;
  const double depth = MedianCameraToDotDistance(obs, PoseNoiseFitGeometry(obs, full), full.dots);
  const double fx = full.intrinsics[kFx];
  if (std::isfinite(depth) && fx > 0) {
    report.mm_per_px = depth * 1e3 / fx;
    report.rms_mm = report.pooled.rms_px * report.mm_per_px;
  }
  report.message += ", each fold's pose-noise solve at the flange pose noise of the whole set";
  std::ostringstream words;
  words << std::setprecision(3) << "the flange pose noise of " << noise.translation_sigma_m * 1e3 << " mm / "
        << noise.rotation_sigma_rad * 180 / M_PI << " deg per axis";
  report.pose_error = words.str();
  return report;
}

FitGeometry PoseNoiseFitGeometry(const ObservationSet& obs, const bundle::PoseNoiseReport& solve) {
  FitGeometry geometry;
  if (!solve.ok || solve.dots.empty()) return geometry;
  const RobotModel robot = RobotOf(obs, solve);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  const CameraIntrinsics camera = WithIntrinsics(obs.camera, solve.intrinsics);
  const std::set<std::pair<std::string, int>> removed(solve.removed.begin(), solve.removed.end());
  std::map<std::string, size_t> index;  // identification pose id -> its correction
  for (size_t i = 0; i < solve.pose_ids.size() && i < solve.corrections.size(); ++i) index[solve.pose_ids[i]] = i;
  for (const PoseObservation& pose : obs.poses) {
    geometry.camera_poses.push_back({pose.id, pose.role, PointsFromCamAt(robot, rho, pose)});
    const auto correction = index.find(pose.id);
    if (pose.role != PoseRole::kIdentification || correction == index.end() || !pose.base_from_flange) continue;
    PoseObservation corrected = pose;
    *corrected.base_from_flange = *pose.base_from_flange * RigidFromTranslationRotvec(solve.corrections[correction->second].data());
    const Rigid3 cam_from_points = PointsFromCamAt(robot, rho, corrected).Inverse();
    for (const auto& [id, pixel] : pose.dots_px) {
      const auto dot = solve.dots.find(id);
      if (dot == solve.dots.end() || removed.count({pose.id, id}) > 0) continue;
      const std::optional<Eigen::Vector2d> uv = Project(camera, cam_from_points * dot->second);
      if (uv) geometry.identification_residuals.push_back({pose.id, id, pixel, pixel - *uv});
    }
  }
  return geometry;
}

}  // namespace selfcal::calibration
