#include "calibration/motion_check.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace selfcal::calibration {

namespace {

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const double at = q * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(at));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

// The images' cameras moved onto the model's frame by one rigid transform (motion_check.h), and each one's
// disagreement with the model's camera.
std::vector<ImageCameraPose> CompareWithModel(const std::vector<std::string>& ids, const std::vector<Rigid3>& images,
                                              const std::vector<Rigid3>& model) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < images.size(); ++k) sum += model[k].rotation * images[k].rotation.transpose();
  Rigid3 model_from_images(NearestRotation(sum), Eigen::Vector3d::Zero());
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < images.size(); ++k) {
    shift += model[k].translation - model_from_images.rotation * images[k].translation;
  }
  model_from_images.translation = shift / static_cast<double>(std::max<size_t>(images.size(), 1));
  std::vector<ImageCameraPose> out;
  for (size_t k = 0; k < images.size(); ++k) {
    ImageCameraPose c;
    c.pose_id = ids[k];
    c.base_from_cam_images = model_from_images * images[k];
    c.base_from_cam_model = model[k];
    c.translation_error_m = (c.base_from_cam_images.translation - model[k].translation).norm();
    c.rotation_error_rad = LogSO3(model[k].rotation.transpose() * c.base_from_cam_images.rotation).norm();
    out.push_back(c);
  }
  return out;
}

}  // namespace

MotionCheck CheckImageMotions(const ObservationSet& obs, const Rigid3& hand_eye,
                              const std::map<int, Eigen::Vector3d>& dots_in_base, const bundle::FreeCameraOptions& options) {
  const bool eye_to_hand = obs.robot.mount == CameraMount::kEyeToHand;
  MotionCheck check;
  if (!obs.UsesFlangePoses()) {
    check.message = "needs a flange pose in every pose";
    return check;
  }
  std::vector<Rigid3> start;
  // The camera in the dots' frame: base_from_flange * flange_from_cam, or flange_from_base * base_from_cam.
  for (const PoseObservation& pose : obs.poses) {
    start.push_back(eye_to_hand ? pose.base_from_flange->Inverse() * hand_eye : *pose.base_from_flange * hand_eye);
  }
  check.images = bundle::RunFreeCameraBundle(obs, start, std::vector<bool>(obs.poses.size(), true), dots_in_base, options);
  if (!check.images.ok) {
    check.message = "the free-camera bundle did not solve: " + check.images.message;
    return check;
  }
  std::vector<double> errors;
  const std::vector<int>& poses = check.images.poses;
  for (size_t a = 0; a < poses.size(); ++a) {
    for (size_t b = a + 1; b < poses.size(); ++b) {
      const PoseObservation& pa = obs.poses[poses[a]];
      const PoseObservation& pb = obs.poses[poses[b]];
      MotionPair pair;
      pair.pose_a = pa.id;
      pair.pose_b = pb.id;
      pair.flange_angle_rad = LogSO3((pa.base_from_flange->Inverse() * *pb.base_from_flange).rotation).norm();
      pair.camera_angle_rad =
          LogSO3((check.images.base_from_cam[a].Inverse() * check.images.base_from_cam[b]).rotation).norm();
      pair.error_rad = std::abs(pair.camera_angle_rad - pair.flange_angle_rad);
      errors.push_back(pair.error_rad);
      check.pairs_over_2deg += pair.error_rad > 2.0 * kPi / 180.0 ? 1 : 0;
      check.pairs.push_back(pair);
    }
  }
  std::vector<std::string> ids;
  std::vector<Rigid3> model;
  for (int i : poses) {
    ids.push_back(obs.poses[i].id);
    model.push_back(start[i]);
  }
  check.cameras = CompareWithModel(ids, check.images.base_from_cam, model);
  check.median_error_rad = Quantile(errors, 0.5);
  check.p90_error_rad = Quantile(errors, 0.9);
  check.max_error_rad = errors.empty() ? 0 : *std::max_element(errors.begin(), errors.end());
  check.ok = !errors.empty();
  std::ostringstream msg;
  msg << check.pairs.size() << " pairs of " << poses.size() << " images: rotation-angle error median "
      << check.median_error_rad * 180 / kPi << " deg, p90 " << check.p90_error_rad * 180 / kPi << " deg, max "
      << check.max_error_rad * 180 / kPi << " deg, " << check.pairs_over_2deg << " over 2 deg";
  check.message = msg.str();
  return check;
}

}  // namespace selfcal::calibration
