#include "simulation/bound_sweep.h"

#include <cmath>
#include <random>

#include "camera/camera.h"
#include "twoview/two_view.h"

namespace selfcal::simulation {

std::vector<BoundSetup> DefaultBoundGrid(double sigma_px) {
  std::vector<BoundSetup> grid;
  for (double fx : {500.0, 1000.0, 2000.0, 4000.0}) {
    for (double spread : {0.05, 0.3, 0.7}) {
      for (double baseline : {0.1, 0.3, 0.6, 1.0}) {
        BoundSetup s;
        s.fx_px = fx;
        s.depth_spread_ratio = spread;
        s.baseline_ratio = baseline;
        s.sigma_px = sigma_px;
        grid.push_back(s);
      }
    }
  }
  // Beyond the grid: a 94 deg lens, and more dots (the bound falls as 1/sqrt(N)) on the best setup.
  for (double fx : {300.0}) {
    for (double baseline : {0.3, 1.0}) {
      BoundSetup s;
      s.fx_px = fx;
      s.depth_spread_ratio = 0.7;
      s.baseline_ratio = baseline;
      s.sigma_px = sigma_px;
      grid.push_back(s);
    }
  }
  for (int n : {800, 8000}) {
    BoundSetup s;
    s.fx_px = 500;
    s.depth_spread_ratio = 0.7;
    s.baseline_ratio = 0.3;
    s.num_points = n;
    s.sigma_px = sigma_px;
    grid.push_back(s);
  }
  return grid;
}

std::vector<BoundPoint> SweepTwoViewBound(const std::vector<BoundSetup>& setups, uint64_t seed,
                                          ProgressSink* progress_sink) {
  std::vector<BoundPoint> out;
  ProgressScope progress(progress_sink, static_cast<int64_t>(setups.size()), "bound sweep setups");
  for (const BoundSetup& setup : setups) {
    BoundPoint point;
    point.setup = setup;
    CameraIntrinsics camera;
    camera.fx_px = setup.fx_px;
    point.horizontal_fov_deg = RadToDeg(2 * std::atan(0.5 * camera.width_px / setup.fx_px));
    const double z = setup.depth_m;
    point.baseline_m = setup.baseline_ratio * z;
    // Camera 2 looks from (b, 0, 0) at the scene centre, aim point offset in y.
    const Eigen::Vector3d centre2(point.baseline_m, 0, 0);
    const Eigen::Vector3d aim(0, 0.1 * z, z);
    const Eigen::Vector3d axis = (aim - centre2).normalized();
    const Eigen::Vector3d x = (Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(axis) * axis).normalized();
    Eigen::Matrix3d r_base_from_cam2;
    r_base_from_cam2 << x, axis.cross(x), axis;
    const Rigid3 cam1_from_cam2(r_base_from_cam2, centre2);
    const Rigid3 cam2_from_cam1 = cam1_from_cam2.Inverse();

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<Eigen::Vector3d> points;
    const double half_u = 0.4 * camera.width_px / setup.fx_px, half_v = 0.4 * camera.height_px / setup.fx_px;
    for (int tries = 0; tries < 100 * setup.num_points + 100000 && static_cast<int>(points.size()) < setup.num_points; ++tries) {
      const double depth = z * (1.0 + 0.5 * setup.depth_spread_ratio * unit(rng));
      const Eigen::Vector3d p(depth * half_u * unit(rng), depth * half_v * unit(rng), depth);
      const auto uv = Project(camera, cam2_from_cam1 * p);
      if (uv && InImage(camera, *uv, 10.0)) points.push_back(p);
    }
    if (static_cast<int>(points.size()) == setup.num_points) {
      const twoview::TwoViewBound unknown = twoview::TwoViewCramerRao(camera, cam2_from_cam1, points, setup.sigma_px, true);
      const twoview::TwoViewBound known = twoview::TwoViewCramerRao(camera, cam2_from_cam1, points, setup.sigma_px, false);
      point.ok_fx_known = known.ok;
      point.ok_fx_unknown = unknown.ok;
      point.orientation_rad_fx_unknown = unknown.rotation_rms_rad();
      point.position_m_fx_unknown = point.baseline_m * unknown.translation_dir_rms_rad();
      point.fx_px = std::sqrt(unknown.fx_variance);
      point.orientation_rad_fx_known = known.rotation_rms_rad();
      point.position_m_fx_known = point.baseline_m * known.translation_dir_rms_rad();
    }
    out.push_back(point);
    progress.Advance();
  }
  return out;
}

}  // namespace selfcal::simulation
