#include "acquisition/dot_prediction.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace selfcal::acquisition {
namespace {

struct Ray {
  Eigen::Vector3d origin;     // camera centre, base frame
  Eigen::Vector3d direction;  // unit, base frame
};

// A dot's 3-D estimate in the base frame.
struct Point {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
};

Ray RayOf(const PredictionModel& m, const Rigid3& base_from_cam, const Eigen::Vector2d& uv) {
  const Eigen::Vector2d xy = PixelToNormalized(m.camera, m.camera.fx_px, uv);
  return {base_from_cam.translation, (base_from_cam.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized()};
}

// Lateral std (m) of a ray at distance z from its camera for the pixel noise.
double LateralSigma(const PredictionModel& m, double z) { return std::max(z, 1e-3) * m.pixel_noise_px / m.camera.fx_px; }

// Weighted linear least squares over the rays; false when the rays do not fix a point in front of them.
bool Triangulate(const PredictionModel& m, const std::vector<Ray>& rays, Point* out) {
  std::vector<double> w(rays.size(), 1.0);
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < rays.size(); ++i) {
      const Eigen::Matrix3d perp = Eigen::Matrix3d::Identity() - rays[i].direction * rays[i].direction.transpose();
      a += w[i] * perp;
      b += w[i] * perp * rays[i].origin;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
    if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) > 1e-9 * eig.eigenvalues()(2))) return false;
    out->p = a.ldlt().solve(b);
    out->cov = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
    for (size_t i = 0; i < rays.size(); ++i) {
      const double z = rays[i].direction.dot(out->p - rays[i].origin);
      if (!(z > 0)) return false;
      const double s = LateralSigma(m, z);
      w[i] = 1.0 / (s * s);
    }
  }
  return out->p.allFinite() && out->cov.allFinite();
}

// Projection of a base-frame point with its covariance, plus the new frame's pixel noise.
bool ProjectPrediction(const PredictionModel& m, const Rigid3& cam_from_base, const Point& x, int id,
                       tracking::PredictedDot* out) {
  const Eigen::Vector3d p = cam_from_base * x.p;
  const std::optional<Eigen::Vector2d> uv = Project(m.camera, p);
  if (!uv) return false;
  Eigen::Matrix<double, 2, 3> j;
  const double h = 1e-6 * std::max(1.0, p.norm());
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d lo = p, hi = p;
    lo[c] -= h;
    hi[c] += h;
    const std::optional<Eigen::Vector2d> a = Project(m.camera, lo), b = Project(m.camera, hi);
    if (!a || !b) return false;
    j.col(c) = (*b - *a) / (2 * h);
  }
  const Eigen::Matrix<double, 2, 3> jb = j * cam_from_base.rotation;
  out->id = id;
  out->uv_px = *uv;
  out->cov_px2 = jb * x.cov * jb.transpose() + m.pixel_noise_px * m.pixel_noise_px * Eigen::Matrix2d::Identity();
  return out->cov_px2.allFinite();
}

double Median(std::vector<double> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

// A single-ray dot at the depth of its triangulated neighbours in the sample that saw it.
bool PointOnRay(const PredictionModel& m, int self, const Ray& ray, const ViewedSample& sample,
                const std::map<int, Point>& points, const DotPredictionOptions& o, Point* out) {
  const Eigen::Vector2d uv = sample.dots_px.at(self);
  std::vector<std::pair<double, double>> neighbours;  // image distance, depth along the ray's camera axis
  for (const auto& [id, px] : sample.dots_px) {
    const auto it = id == self ? points.end() : points.find(id);
    if (it == points.end()) continue;
    neighbours.push_back({(px - uv).norm(), ray.direction.dot(it->second.p - ray.origin)});
  }
  if (static_cast<int>(neighbours.size()) < o.min_depth_neighbours) return false;
  const size_t k = std::min(neighbours.size(), static_cast<size_t>(o.depth_neighbours));
  std::partial_sort(neighbours.begin(), neighbours.begin() + static_cast<std::ptrdiff_t>(k), neighbours.end());
  std::vector<double> depths;
  for (size_t i = 0; i < k; ++i) depths.push_back(neighbours[i].second);
  const double z = Median(depths);
  if (!(z > 0)) return false;
  double spread = 0;
  for (double d : depths) spread = std::max(spread, std::abs(d - z));
  const double sigma_z = std::max(spread, o.min_depth_sigma_fraction * z);
  const double lateral = LateralSigma(m, z);
  const Eigen::Matrix3d along = ray.direction * ray.direction.transpose();
  out->p = ray.origin + z * ray.direction;
  out->cov = sigma_z * sigma_z * along + lateral * lateral * (Eigen::Matrix3d::Identity() - along);
  return true;
}

// The rays of every dot, by id: (sample index, ray); the current frame's as sample index -1.
using RaysById = std::map<int, std::vector<std::pair<int, Ray>>>;

std::map<int, Point> TriangulateAll(const PredictionModel& model, const RaysById& rays, bool with_current) {
  std::map<int, Point> points;
  for (const auto& [id, r] : rays) {
    std::vector<Ray> plain;
    for (const auto& sr : r) {
      if (with_current || sr.first >= 0) plain.push_back(sr.second);
    }
    Point x;
    if (plain.size() >= 2 && Triangulate(model, plain, &x)) points[id] = x;
  }
  return points;
}

}  // namespace

DotPredictionReport PredictDots(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                const Eigen::VectorXd& joints_rad, const std::map<int, Eigen::Vector2d>& current_px,
                                const DotPredictionOptions& options) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model.robot);
  RaysById rays;
  for (size_t s = 0; s < samples.size(); ++s) {
    const Rigid3 base_from_cam = BaseFromCam(model.robot, rho, samples[s].joints_rad);
    for (const auto& [id, uv] : samples[s].dots_px) rays[id].push_back({static_cast<int>(s), RayOf(model, base_from_cam, uv)});
  }
  const Rigid3 base_from_cam_now = BaseFromCam(model.robot, rho, joints_rad);
  RaysById with_current = rays;
  for (const auto& [id, uv] : current_px) {
    if (rays.count(id)) with_current[id].push_back({-1, RayOf(model, base_from_cam_now, uv)});
  }
  const std::map<int, Point> points = TriangulateAll(model, rays, false);
  const std::map<int, Point> depth_points = TriangulateAll(model, with_current, true);
  DotPredictionReport report;
  const Rigid3 cam_from_base = base_from_cam_now.Inverse();
  for (const auto& [id, r] : rays) {
    Point x;
    bool have = false;
    if (const auto it = points.find(id); it != points.end()) {
      x = it->second;
      have = true;
      ++report.triangulated;
    } else {
      // One ray (or rays that fix no point): the latest sample's ray at its neighbours' depth.
      const auto& [s, ray] = r.back();
      have = PointOnRay(model, id, ray, samples[static_cast<size_t>(s)], depth_points, options, &x);
      report.single_ray += have ? 1 : 0;
    }
    tracking::PredictedDot p;
    if (have && ProjectPrediction(model, cam_from_base, x, id, &p) && InImage(model.camera, p.uv_px, -options.image_margin_px)) {
      report.dots.push_back(p);
    } else {
      ++report.not_predicted;
    }
  }
  return report;
}

}  // namespace selfcal::acquisition
