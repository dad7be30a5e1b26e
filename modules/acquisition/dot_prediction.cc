#include "acquisition/dot_prediction.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "tracking/planar_fit.h"

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

// A pixel through a correction (the identity when none was fitted).
Eigen::Vector2d MapPixel(const tracking::PredictionCorrection& c, const Eigen::Vector2d& uv) {
  return c.ok ? tracking::MapPoint(c.observed_from_predicted, uv) : uv;
}

// Lateral std (m) of a ray at distance z from its camera: the pixel noise and the nominal model's own
// error per ray, which the rays of a nominal model carry into every triangulation.
double LateralSigma(const PredictionModel& m, double ray_model_sigma_px, double z) {
  return std::max(z, 1e-3) * std::hypot(m.pixel_noise_px, ray_model_sigma_px) / m.camera.fx_px;
}

// Weighted linear least squares over the rays; false when the rays do not fix a point in front of them.
bool Triangulate(const PredictionModel& m, double ray_model_sigma_px, const std::vector<Ray>& rays, Point* out) {
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
      const double s = LateralSigma(m, ray_model_sigma_px, z);
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

// A single-ray dot anywhere in the depth range of the scene as that sample saw it: the depths (along its
// camera axis) of the sample's triangulated dots, widened by a margin. Its prediction is the segment of
// its epipolar line between the projections of the nearest and farthest depth, as a gate whose
// boundary holds the whole segment: a dot's image neighbours say nothing of its depth in a scene of
// scattered dots, so nothing narrower is honest.
bool SegmentOnRay(const PredictionModel& m, int self, const Ray& ray, const Rigid3& cam_from_base,
                  const Rigid3& sample_cam_from_base, const ViewedSample& sample, const std::map<int, Point>& points,
                  const DotPredictionOptions& o, tracking::PredictedDot* out) {
  double z_min = 0, z_max = 0;
  int depths = 0;
  for (const auto& [id, px] : sample.dots_px) {
    const auto it = id == self ? points.end() : points.find(id);
    if (it == points.end()) continue;
    const double z = (sample_cam_from_base * it->second.p).z();
    if (!(z > 0)) continue;
    z_min = depths == 0 ? z : std::min(z_min, z);
    z_max = depths == 0 ? z : std::max(z_max, z);
    ++depths;
  }
  if (depths < o.min_depth_neighbours) return false;
  const double axis = sample_cam_from_base.rotation.row(2).dot(ray.direction);  // depth per unit along the ray
  if (!(axis > 0)) return false;
  const double near = z_min * (1 - o.depth_margin_fraction) / axis, far = z_max * (1 + o.depth_margin_fraction) / axis;
  const std::optional<Eigen::Vector2d> a = Project(m.camera, cam_from_base * (ray.origin + near * ray.direction));
  const std::optional<Eigen::Vector2d> b = Project(m.camera, cam_from_base * (ray.origin + far * ray.direction));
  if (!a || !b) return false;
  const Eigen::Vector2d d = *b - *a;
  const double half = 0.5 * d.norm();
  const Eigen::Vector2d dir = half > 1e-9 ? Eigen::Vector2d(d / d.norm()) : Eigen::Vector2d::UnitX();
  const double noise2 = m.pixel_noise_px * m.pixel_noise_px + o.ray_model_sigma_px * o.ray_model_sigma_px;
  out->id = self;
  out->uv_px = 0.5 * (*a + *b);
  // The segment's ends at half the gate along it: the other half is left for the noise across it there.
  out->cov_px2 = (2 * half * half / o.segment_gate_chi2) * dir * dir.transpose() + noise2 * Eigen::Matrix2d::Identity();
  return out->cov_px2.allFinite();
}

// The rays of every dot, by id: (sample index, ray); the current frame's as sample index -1.
using RaysById = std::map<int, std::vector<std::pair<int, Ray>>>;

std::map<int, Point> TriangulateAll(const PredictionModel& model, double ray_model_sigma_px, const RaysById& rays,
                                    bool with_current) {
  std::map<int, Point> points;
  for (const auto& [id, r] : rays) {
    std::vector<Ray> plain;
    for (const auto& sr : r) {
      if (with_current || sr.first >= 0) plain.push_back(sr.second);
    }
    Point x;
    if (plain.size() >= 2 && Triangulate(model, ray_model_sigma_px, plain, &x)) points[id] = x;
  }
  return points;
}

// The rays of every sample's dots, each sample's pixels through its correction.
RaysById SampleRays(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                    const std::vector<Rigid3>& base_from_cams,
                    const std::vector<tracking::PredictionCorrection>& corrections) {
  RaysById rays;
  for (size_t s = 0; s < samples.size(); ++s) {
    for (const auto& [id, uv] : samples[s].dots_px) {
      rays[id].push_back({static_cast<int>(s), RayOf(model, base_from_cams[s], MapPixel(corrections[s], uv))});
    }
  }
  return rays;
}

// Each sample's pixels mapped onto its nominal camera: the nominal model puts every sample's camera a
// little off, by an amount that differs from pose to pose, so rays from distant poses miss each other
// and a point triangulated from them is off in a way no correction of the new frame can remove. For
// each sample after the first (which holds the gauge), the robust planar map from its observed pixels
// to the projections of the points triangulated from all samples absorbs most of its camera's error;
// a few rounds of triangulating and mapping make the rays agree.
std::vector<tracking::PredictionCorrection> SampleCorrections(const PredictionModel& model,
                                                              const std::vector<ViewedSample>& samples,
                                                              const std::vector<Rigid3>& base_from_cams,
                                                              const DotPredictionOptions& options) {
  std::vector<tracking::PredictionCorrection> corrections(samples.size());
  for (int round = 0; round < options.sample_correction_rounds && samples.size() > 2; ++round) {
    const RaysById rays = SampleRays(model, samples, base_from_cams, corrections);
    const std::map<int, Point> points = TriangulateAll(model, options.ray_model_sigma_px, rays, false);
    for (size_t s = 1; s < samples.size(); ++s) {
      const Rigid3 cam_from_base = base_from_cams[s].Inverse();
      std::vector<Eigen::Vector2d> observed, nominal;
      for (const auto& [id, uv] : samples[s].dots_px) {
        const auto it = points.find(id);
        if (it == points.end() || rays.at(id).size() < 3) continue;
        if (const std::optional<Eigen::Vector2d> p = Project(model.camera, cam_from_base * it->second.p)) {
          observed.push_back(uv);
          nominal.push_back(*p);
        }
      }
      if (static_cast<int>(observed.size()) < options.min_sample_correction_dots) continue;
      tracking::PredictionCorrection c =
          tracking::FitPredictionCorrection(observed, nominal, tracking::PredictionCorrectionOptions());
      if (c.ok) corrections[s] = c;
    }
  }
  return corrections;
}

}  // namespace

DotPredictionReport PredictDots(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                const Eigen::VectorXd& joints_rad, const std::map<int, Eigen::Vector2d>& current_px,
                                const DotPredictionOptions& options) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model.robot);
  std::vector<Rigid3> base_from_cams;  // of every sample, once
  for (size_t s = 0; s < samples.size(); ++s) base_from_cams.push_back(BaseFromCam(model.robot, rho, samples[s].joints_rad));
  const std::vector<tracking::PredictionCorrection> corrections =
      SampleCorrections(model, samples, base_from_cams, options);
  const RaysById rays = SampleRays(model, samples, base_from_cams, corrections);
  const Rigid3 base_from_cam_now = BaseFromCam(model.robot, rho, joints_rad);
  RaysById with_current = rays;
  for (const auto& [id, uv] : current_px) {
    if (rays.count(id)) with_current[id].push_back({-1, RayOf(model, base_from_cam_now, uv)});
  }
  // A candidate of the latest sample is a second ray of its dot for the points, never for the depths.
  RaysById with_candidates = rays;
  if (!samples.empty()) {
    const size_t last = samples.size() - 1;
    const Rigid3& base_from_cam = base_from_cams[last];
    for (const auto& [id, uv] : samples[last].candidates_px) {
      if (rays.count(id)) {
        with_candidates[id].push_back({static_cast<int>(last), RayOf(model, base_from_cam, MapPixel(corrections[last], uv))});
      }
    }
  }
  const std::map<int, Point> points = TriangulateAll(model, options.ray_model_sigma_px, with_candidates, false);
  const std::map<int, Point> depth_points = TriangulateAll(model, options.ray_model_sigma_px, with_current, true);
  DotPredictionReport report;
  const Rigid3 cam_from_base = base_from_cam_now.Inverse();
  for (const auto& [id, uv] : current_px) {
    Eigen::Vector3d x;
    if (const auto own = points.find(id); own != points.end()) {
      x = own->second.p;
    } else if (const auto pair = depth_points.find(id); pair != depth_points.end() && rays.count(id)) {
      // On the sample's ray, at the depth the new ray gives: off the tracked pixel only by the model's
      // error across the epipolar line (the pair's own point would agree with the new ray by construction).
      const Ray& ray = rays.at(id).back().second;
      x = ray.origin + ray.direction.dot(pair->second.p - ray.origin) * ray.direction;
    } else {
      continue;
    }
    if (const std::optional<Eigen::Vector2d> a = Project(model.camera, cam_from_base * x)) report.anchor_px[id] = *a;
  }
  for (const auto& [id, r] : rays) {
    // One ray (or rays that fix no point): the latest sample's ray over the scene's depth range.
    auto segment = [&](tracking::PredictedDot* p) {
      const auto& [s, ray] = r.back();
      const Rigid3 sample_cam_from_base = base_from_cams[static_cast<size_t>(s)].Inverse();
      return SegmentOnRay(model, id, ray, cam_from_base, sample_cam_from_base, samples[static_cast<size_t>(s)],
                          depth_points, options, p);
    };
    tracking::PredictedDot p;
    bool have = false;
    if (const auto it = points.find(id); it != points.end()) {
      have = ProjectPrediction(model, cam_from_base, it->second, id, &p);
      ++report.triangulated;
      // A point that rests on a candidate may be wrong: the dot may still lie anywhere on its segment,
      // which competes beside the point's gate.
      tracking::PredictedDot whole;
      if (have && r.size() == 1 && segment(&whole) && InImage(model.camera, whole.uv_px, -options.image_margin_px)) {
        whole.names = false;
        report.dots.push_back(whole);
        ++report.on_candidates;
      }
    } else {
      have = segment(&p);
      report.single_ray += have ? 1 : 0;
    }
    if (have && InImage(model.camera, p.uv_px, -options.image_margin_px)) {
      report.dots.push_back(p);
    } else {
      ++report.not_predicted;
    }
  }
  return report;
}

}  // namespace selfcal::acquisition
