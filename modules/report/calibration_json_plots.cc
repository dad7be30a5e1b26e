#include "report/calibration_json_plots.h"

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"
#include "report/json_util.h"

namespace selfcal::report {

namespace {

using nlohmann::json;

json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }


// The correlations of the estimated entries, named (order: free parameters, then the estimated intrinsics).
json CorrelationJson(const ObservationSet& obs, const bundle::BundleReport& b) {
  if (!b.covariance_available || b.correlation_free.rows() == 0) return nullptr;
  const KinematicParameters params(obs.robot.num_joints());
  json names = json::array();
  for (int i : b.free_indices) names.push_back(params.name(i));
  for (int i : EstimatedIntrinsics(b.intrinsics_estimated)) names.push_back(IntrinsicName(i));
  if (static_cast<int>(names.size()) != b.correlation_free.rows()) return nullptr;
  json matrix = json::array();
  for (int r = 0; r < b.correlation_free.rows(); ++r) {
    json row = json::array();
    for (int c = 0; c < b.correlation_free.cols(); ++c) row.push_back(Finite(b.correlation_free(r, c)));
    matrix.push_back(row);
  }
  return {{"names", names}, {"matrix", matrix}};
}

// The correlations of the pose-noise solve's covariance: the camera correction (cam.tx .. cam.rz), then the
// estimated intrinsics.
json PoseNoiseCorrelationJson(const ObservationSet& obs, const bundle::PoseNoiseReport& n) {
  const int size = static_cast<int>(n.covariance.rows());
  if (size == 0) return nullptr;
  const KinematicParameters params(obs.robot.num_joints());
  json names = json::array();
  for (int k = 0; k < 6; ++k) names.push_back(params.name(params.CamOffset() + k));
  for (int i : EstimatedIntrinsics(n.intrinsics_estimated)) names.push_back(IntrinsicName(i));
  if (static_cast<int>(names.size()) != size) return nullptr;
  const Eigen::VectorXd sd = n.covariance.diagonal().cwiseSqrt();
  json matrix = json::array();
  for (int r = 0; r < size; ++r) {
    json row = json::array();
    for (int c = 0; c < size; ++c) row.push_back(Finite(n.covariance(r, c) / (sd[r] * sd[c])));
    matrix.push_back(row);
  }
  return {{"names", names}, {"matrix", matrix}};
}

json CamerasJson(const calibration::FitGeometry& g) {
  json cameras = json::array();
  for (const calibration::CameraPose& c : g.camera_poses) {
    cameras.push_back({{"pose", c.pose_id},
                       {"role", PoseRoleName(c.role)},
                       {"xyz_m", Vector(c.base_from_cam.translation)},
                       {"rotvec_rad", Vector(LogSO3(c.base_from_cam.rotation))}});
  }
  return cameras;
}

}  // namespace

json ResidualsJson(const std::vector<calibration::ObservedResidual>& residuals) {
  json rows = json::array();
  for (const calibration::ObservedResidual& r : residuals) {
    rows.push_back({{"pose", r.pose_id},
                    {"dot", r.dot_id},
                    {"pixel_px", {r.pixel_px.x(), r.pixel_px.y()}},
                    {"residual_px", {r.residual_px.x(), r.residual_px.y()}}});
  }
  return rows;
}

json BundlePlotDataJson(const ObservationSet& obs, const calibration::BundleStageReport& stage) {
  const calibration::FitGeometry& g = stage.fit_geometry;
  if (g.camera_poses.empty()) return nullptr;
  const json cameras = CamerasJson(g);
  json dots = json::array();
  for (const auto& [id, p] : stage.bundle.dots_in_base) dots.push_back({{"dot", id}, {"xyz_m", Vector(p)}});
  return {{"description", "for report.html's figures: camera_poses_from_model, the calibrated model's base_from_cam at every "
                          "pose (the recorded joints or flange pose through the calibrated model and hand-eye transform, "
                          "not the image's own camera pose; translation and rotation vector, in the base frame of the "
                          "bundle's gauge), the bundle's dots in that frame, "
                          "every identification detection of the final fit and every held-out detection with its "
                          "residual (detection - prediction, px), and the correlations of the estimated entries"},
          {"image", {{"width_px", obs.camera.width_px}, {"height_px", obs.camera.height_px}}},
          {"camera_poses_from_model", cameras},
          {"dots_in_base", dots},
          {"identification_residuals", ResidualsJson(g.identification_residuals)},
          {"heldout_residuals", ResidualsJson(stage.heldout.residuals)},
          {"correlation", CorrelationJson(obs, stage.bundle)}};
}

json PoseNoisePlotDataJson(const ObservationSet& obs, const calibration::CalibrationReport& report) {
  const calibration::FitGeometry& g = report.pose_noise_fit_geometry;
  if (!report.PoseNoiseIsTheResult() || g.camera_poses.empty()) return nullptr;
  json dots = json::array();
  for (const auto& [id, p] : report.pose_noise->dots) dots.push_back({{"dot", id}, {"xyz_m", Vector(p)}});
  return {{"description", "for report.html's figures, from the pose-noise solve (the model written): "
                          "camera_poses_from_model, its base_from_cam at every pose (the recorded flange pose times its "
                          "hand-eye transform, not the corrected flange pose), its dots, every identification detection "
                          "of its final fit (at the corrected flange poses) and every held-out detection with its "
                          "residual (detection - prediction, px), and the correlations of its hand-eye correction and "
                          "estimated intrinsics"},
          {"image", {{"width_px", obs.camera.width_px}, {"height_px", obs.camera.height_px}}},
          {"camera_poses_from_model", CamerasJson(g)},
          {"dots_in_base", dots},
          {"identification_residuals", ResidualsJson(g.identification_residuals)},
          {"heldout_residuals",
           ResidualsJson(report.pose_noise_heldout ? report.pose_noise_heldout->residuals
                                                   : std::vector<calibration::ObservedResidual>())},
          {"correlation", PoseNoiseCorrelationJson(obs, *report.pose_noise)}};
}

}  // namespace selfcal::report
