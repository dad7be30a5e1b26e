#include "acquisition/bundled_cameras.h"

#include <map>

#include "bundle/free_camera_bundle.h"
#include "observations/observation_set.h"

namespace selfcal::acquisition {

BundledCameras BundleSampleCameras(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                   const DotPredictionOptions& options) {
  BundledCameras out;
  if (samples.size() < 3) {
    out.message = "fewer than three samples";
    return out;
  }
  const std::vector<Rigid3> start = SampleCameras(model, samples, options);
  ObservationSet set;
  set.robot = model.robot;
  set.camera = model.camera;
  set.pixel_noise_px = model.pixel_noise_px;
  std::map<int, std::vector<Ray>> rays;
  for (size_t s = 0; s < samples.size(); ++s) {
    PoseObservation pose;
    pose.id = "s" + std::to_string(s);
    pose.joints_rad = samples[s].joints_rad;
    pose.dots_px = samples[s].dots_px;
    set.poses.push_back(pose);
    for (const auto& [id, uv] : samples[s].dots_px) rays[id].push_back(RayOf(model, start[s], uv));
  }
  std::map<int, Eigen::Vector3d> dots;
  for (const auto& [id, r] : rays) {
    Point x;
    if (r.size() >= 2 && Triangulate(model, options.ray_model_sigma_px, r, &x)) dots[id] = x.p;
  }
  const bundle::FreeCameraReport solved = bundle::RunFreeCameraBundle(
      set, start, std::vector<bool>(samples.size(), true), dots, bundle::FreeCameraOptions());
  out.message = solved.message;
  if (!solved.ok || solved.base_from_cam.size() != samples.size()) return out;
  out.ok = true;
  out.base_from_cams = solved.base_from_cam;
  out.fx_px = solved.intrinsics[kFx];
  out.rms_reprojection_px = solved.rms_reprojection_px;
  return out;
}

void UseBundledCameras(const BundledCameras& bundled, PredictionModel* model, std::vector<ViewedSample>* samples) {
  if (!bundled.ok || bundled.base_from_cams.size() != samples->size()) return;
  model->camera.fx_px = bundled.fx_px;
  for (size_t s = 0; s < samples->size(); ++s) (*samples)[s].base_from_cam = bundled.base_from_cams[s];
}

}  // namespace selfcal::acquisition
