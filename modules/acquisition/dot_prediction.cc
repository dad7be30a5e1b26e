#include "acquisition/dot_prediction.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace selfcal::acquisition {

Ray RayOf(const PredictionModel& m, const Rigid3& base_from_cam, const Eigen::Vector2d& uv) {
  const Eigen::Vector2d xy = PixelToNormalized(m.camera, m.camera.fx_px, uv);
  return {base_from_cam.translation, (base_from_cam.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized()};
}

namespace {

// Lateral std (m) of a ray at distance z from its camera: the pixel noise and the nominal model's own
// error per ray, which the rays of a nominal model carry into every triangulation.
double LateralSigma(const PredictionModel& m, double ray_model_sigma_px, double z) {
  return std::max(z, 1e-3) * std::hypot(m.pixel_noise_px, ray_model_sigma_px) / m.camera.fx_px;
}

}  // namespace

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

namespace {

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

// The rays of every sample's dots.
RaysById SampleRays(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                    const std::vector<Rigid3>& base_from_cams) {
  RaysById rays;
  for (size_t s = 0; s < samples.size(); ++s) {
    for (const auto& [id, uv] : samples[s].dots_px) {
      rays[id].push_back({static_cast<int>(s), RayOf(model, base_from_cams[s], uv)});
    }
  }
  return rays;
}

// The camera of a frame resected on its dots that have points: cv::solvePnP (iterative, from `guess`)
// in normalised coordinates, then once more without the dots off by more than the larger of
// `inlier_px` and three times the median. Empty when fewer than `min_dots` remain, the solve fails, or
// fewer than `min_agreeing_fraction` of all the dots lie within `inlier_px` of the pose's projection.
std::optional<Rigid3> Resect(const PredictionModel& m, const Rigid3& base_from_cam_guess,
                             const std::map<int, Eigen::Vector2d>& px, const std::map<int, Point>& points,
                             int min_dots, double inlier_px, double min_agreeing_fraction) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const auto& [id, uv] : px) {
    const auto it = points.find(id);
    if (it == points.end()) continue;
    const Eigen::Vector2d xy = PixelToNormalized(m.camera, m.camera.fx_px, uv);
    object.emplace_back(it->second.p.x(), it->second.p.y(), it->second.p.z());
    image.emplace_back(xy.x(), xy.y());
  }
  const std::vector<cv::Point3d> all_object = object;
  const std::vector<cv::Point2d> all_image = image;
  const Rigid3 guess = base_from_cam_guess.Inverse();
  cv::Mat r, rvec(3, 1, CV_64F), tvec(3, 1, CV_64F);
  cv::eigen2cv(guess.rotation, r);
  cv::Rodrigues(r, rvec);
  for (int k = 0; k < 3; ++k) tvec.at<double>(k) = guess.translation[k];
  // Each dot's distance (px) from the projection of the pose at rvec, tvec.
  auto errors_px = [&](const std::vector<cv::Point3d>& points_3d, const std::vector<cv::Point2d>& observed) {
    std::vector<cv::Point2d> reprojected;
    cv::projectPoints(points_3d, rvec, tvec, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), reprojected);
    std::vector<double> error(points_3d.size());
    for (size_t k = 0; k < points_3d.size(); ++k) error[k] = m.camera.fx_px * cv::norm(reprojected[k] - observed[k]);
    return error;
  };
  for (int pass = 0; pass < 2; ++pass) {
    if (static_cast<int>(object.size()) < min_dots) return std::nullopt;
    if (!cv::solvePnP(object, image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, true,
                      cv::SOLVEPNP_ITERATIVE)) {
      return std::nullopt;
    }
    const std::vector<double> error_px = errors_px(object, image);
    std::vector<double> sorted = error_px;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double limit = std::max(inlier_px, 3 * sorted[sorted.size() / 2]);
    std::vector<cv::Point3d> kept_object;
    std::vector<cv::Point2d> kept_image;
    for (size_t k = 0; k < object.size(); ++k) {
      if (error_px[k] <= limit) {
        kept_object.push_back(object[k]);
        kept_image.push_back(image[k]);
      }
    }
    if (pass == 1 || kept_object.size() == object.size()) break;
    object.swap(kept_object);
    image.swap(kept_image);
  }
  // Most of the dots must agree with the pose: when many are wrong (a tracker that jumped onto other
  // blobs), the pose they give is no better than the nominal one, and the robust correction downstream
  // (tracking/predicted_match.h) is what finds them out.
  const std::vector<double> all_error_px = errors_px(all_object, all_image);
  const auto agree = std::count_if(all_error_px.begin(), all_error_px.end(), [&](double e) { return e <= inlier_px; });
  if (static_cast<double>(agree) < min_agreeing_fraction * static_cast<double>(all_object.size())) return std::nullopt;
  cv::Rodrigues(rvec, r);
  Rigid3 cam_from_base;
  cv::cv2eigen(r, cam_from_base.rotation);
  for (int k = 0; k < 3; ++k) cam_from_base.translation[k] = tvec.at<double>(k);
  if (!cam_from_base.rotation.allFinite() || !cam_from_base.translation.allFinite()) return std::nullopt;
  return cam_from_base.Inverse();
}

// Each sample's camera resected on the points: the nominal model puts every sample's camera a little
// off, by an amount that differs from pose to pose, so rays from distant poses miss each other and a
// point triangulated from them is off in a way no correction of the new frame can remove. For each
// sample after the first (which holds the gauge), the camera that projects the points triangulated from
// all samples (those with three rays or more) onto its pixels replaces the nominal one; a few rounds of
// triangulating and resecting make the rays agree. A pose, not a planar map of pixels: a dot nearer or
// farther than the scene's middle keeps its parallax (a planar map put the epipolar lines of dots seen
// once 11-16 px off in later frames).
std::vector<Rigid3> ResectSamples(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                  std::vector<Rigid3> base_from_cams, const DotPredictionOptions& options) {
  for (int round = 0; round < options.sample_correction_rounds && samples.size() > 2; ++round) {
    const RaysById rays = SampleRays(model, samples, base_from_cams);
    std::map<int, Point> points = TriangulateAll(model, options.ray_model_sigma_px, rays, false);
    for (auto it = points.begin(); it != points.end();) it = rays.at(it->first).size() < 3 ? points.erase(it) : std::next(it);
    for (size_t s = 1; s < samples.size(); ++s) {
      if (samples[s].base_from_cam) continue;
      if (const std::optional<Rigid3> c = Resect(model, base_from_cams[s], samples[s].dots_px, points,
                                                 options.min_sample_correction_dots, options.resection_inlier_px,
                                                 options.min_resection_agreeing_fraction)) {
        base_from_cams[s] = *c;
      }
    }
  }
  return base_from_cams;
}

}  // namespace

std::vector<Rigid3> SampleCameras(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                  const DotPredictionOptions& options) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model.robot);
  std::vector<Rigid3> base_from_cams;
  bool all_given = true;
  for (const ViewedSample& s : samples) {
    base_from_cams.push_back(s.base_from_cam ? *s.base_from_cam : PointsFromCam(model.robot, rho, s.joints_rad));
    all_given = all_given && s.base_from_cam.has_value();
  }
  if (all_given) return base_from_cams;
  return ResectSamples(model, samples, std::move(base_from_cams), options);
}

DotPredictionReport PredictDots(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                const Eigen::VectorXd& joints_rad, const std::map<int, Eigen::Vector2d>& current_px,
                                const DotPredictionOptions& options) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model.robot);
  const std::vector<Rigid3> base_from_cams = SampleCameras(model, samples, options);  // of every sample, once
  const RaysById rays = SampleRays(model, samples, base_from_cams);
  // The new frame's camera, resected on the dots already known in it when enough of them have points.
  Rigid3 base_from_cam_now = PointsFromCam(model.robot, rho, joints_rad);
  if (options.resect_new_frame && samples.size() >= 2) {
    const std::map<int, Point> sample_points = TriangulateAll(model, options.ray_model_sigma_px, rays, false);
    if (const std::optional<Rigid3> c = Resect(model, base_from_cam_now, current_px, sample_points,
                                               options.min_sample_correction_dots, options.resection_inlier_px,
                                                 options.min_resection_agreeing_fraction)) {
      base_from_cam_now = *c;
    }
  }
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
      if (rays.count(id)) with_candidates[id].push_back({static_cast<int>(last), RayOf(model, base_from_cam, uv)});
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
  for (const auto& entry : rays) {
    const int id = entry.first;  // named, not a structured binding: lambdas capture those only from C++20
    const auto& r = entry.second;
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
