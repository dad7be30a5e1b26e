#include "calibration/fit_geometry.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "camera/camera.h"

namespace selfcal::calibration {

FitGeometry FitGeometryOf(const ObservationSet& obs, const bundle::BundleReport& b) {
  FitGeometry geometry;
  // No dots: the bundle stopped before its solve (degenerate, no scale), and rho is only its start.
  if (b.dots_in_base.empty() || b.rho.size() != obs.robot.num_parameters() || !b.rho.allFinite() ||
      !(std::isfinite(b.fx_px) && b.fx_px > 0)) {
    return geometry;
  }
  // The bundle's camera: the held intrinsics are the observations' own (their start values).
  const CameraIntrinsics camera = WithIntrinsics(obs.camera, b.intrinsics);
  std::set<std::pair<std::string, int>> removed;
  for (const bundle::RemovedObservation& o : b.removed) removed.insert({o.pose_id, o.dot_id});
  for (const PoseObservation& pose : obs.poses) {
    const Rigid3 base_from_cam = PointsFromCamAt(obs.robot, b.rho, pose);
    geometry.camera_poses.push_back({pose.id, pose.role, base_from_cam});
    if (pose.role != PoseRole::kIdentification) continue;
    const Rigid3 cam_from_base = base_from_cam.Inverse();
    for (const auto& [id, pixel] : pose.dots_px) {
      const auto dot = b.dots_in_base.find(id);
      if (dot == b.dots_in_base.end() || removed.count({pose.id, id}) > 0) continue;
      const std::optional<Eigen::Vector2d> uv = Project(camera, cam_from_base * dot->second);
      if (!uv) continue;
      geometry.identification_residuals.push_back({pose.id, id, pixel, pixel - *uv});
    }
  }
  return geometry;
}

double MedianCameraToDotDistance(const ObservationSet& obs, const FitGeometry& geometry,
                                 const std::map<int, Eigen::Vector3d>& dots_in_base) {
  std::vector<double> depths;
  const std::vector<CameraPose>& cameras = geometry.camera_poses;
  for (size_t p = 0; p < cameras.size() && p < obs.poses.size(); ++p) {
    if (cameras[p].role != PoseRole::kIdentification) continue;
    for (const auto& entry : obs.poses[p].dots_px) {
      auto dot = dots_in_base.find(entry.first);
      if (dot != dots_in_base.end()) depths.push_back((dot->second - cameras[p].base_from_cam.translation).norm());
    }
  }
  if (depths.empty()) return NAN;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

}  // namespace selfcal::calibration
