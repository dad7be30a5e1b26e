#include "simulation/rendered_observations.h"

#include <cmath>
#include <limits>

#include "sim/simulated_camera.h"

namespace selfcal::simulation {

void CentroidErrors::Append(const CentroidErrors& other) {
  expected += other.expected;
  detected += other.detected;
  matched += other.matched;
  missed += other.missed;
  spurious += other.spurious;
  vs_projected_px.insert(vs_projected_px.end(), other.vs_projected_px.begin(), other.vs_projected_px.end());
  vs_area_centroid_px.insert(vs_area_centroid_px.end(), other.vs_area_centroid_px.begin(),
                             other.vs_area_centroid_px.end());
  ellipse_bias_px.insert(ellipse_bias_px.end(), other.ellipse_bias_px.begin(), other.ellipse_bias_px.end());
}

double CentroidErrors::Rms(const std::vector<double>& values) {
  if (values.empty()) return std::nan("");
  double sum = 0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

ObservationSet ObserveRendered(const sim::SimResult& world, const RenderedObservationOptions& options,
                               uint64_t noise_seed, CentroidErrors* errors) {
  ObservationSet set = world.observations;
  set.pixel_noise_px = options.assumed_noise_px;
  const sim::DotScene scene = sim::MakeDotScene(world.truth, options.dot_radius_m);
  CentroidErrors local;
  for (size_t i = 0; i < set.poses.size(); ++i) {
    PoseObservation& pose = set.poses[i];
    pose.dots_px.clear();
    const sim::RenderedImage image =
        sim::RenderDots(world.truth.camera_true, world.truth.base_from_cam[i], scene, options.render,
                        sim::FrameNoiseSeed(noise_seed, static_cast<int64_t>(i)));
    const tracking::DetectionReport report = tracking::DetectDots(image.image, options.detector);
    local.detected += static_cast<int>(report.dots.size());
    // Nearest true centre within the match radius; a dot claimed twice keeps neither claim.
    std::vector<Eigen::Vector2d> centroids;
    for (const tracking::DotDetection& d : report.dots) centroids.push_back(d.centroid_px);
    const std::vector<int> names = sim::NameByNearestDisc(image, centroids, options.match_radius_px);
    std::vector<int> owner(image.dots.size(), -1);  // dot id -> its detection
    for (size_t k = 0; k < names.size(); ++k) {
      if (names[k] >= 0) {
        owner[names[k]] = static_cast<int>(k);
      } else {
        ++local.spurious;
      }
    }
    for (const sim::RenderedDot& dot : image.dots) {
      const int k = owner[dot.id];
      if (dot.Clean()) ++local.expected;
      if (k < 0) {
        if (dot.Clean()) ++local.missed;
        continue;
      }
      ++local.matched;
      const Eigen::Vector2d c = report.dots[k].centroid_px;
      pose.dots_px[dot.id] = c;
      if (!dot.Clean()) continue;
      for (int a = 0; a < 2; ++a) {
        local.vs_projected_px.push_back(c[a] - dot.projected_centre_px[a]);
        local.vs_area_centroid_px.push_back(c[a] - dot.area_centroid_px[a]);
        local.ellipse_bias_px.push_back(dot.area_centroid_px[a] - dot.projected_centre_px[a]);
      }
    }
  }
  if (errors != nullptr) errors->Append(local);
  return set;
}

}  // namespace selfcal::simulation
