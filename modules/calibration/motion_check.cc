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

}  // namespace

MotionCheck CheckImageMotions(const ObservationSet& obs, const Rigid3& flange_from_cam,
                              const std::map<int, Eigen::Vector3d>& dots_in_base, const bundle::FreeCameraOptions& options) {
  MotionCheck check;
  if (!obs.UsesFlangePoses()) {
    check.message = "needs a flange pose in every pose";
    return check;
  }
  std::vector<Rigid3> start;
  for (const PoseObservation& pose : obs.poses) start.push_back(*pose.base_from_flange * flange_from_cam);
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
