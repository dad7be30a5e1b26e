#include "identification/triangulation.h"

#include <cmath>
#include <sstream>

#include <vector>

#include <Eigen/Dense>

#include "base/status.h"

namespace selfcal::identification {

namespace {

// Smallest angle between two viewing lines that still fixes depth; below it the rays are treated as
// parallel (0.01 deg: 1 m away that needs a 0.2 mm baseline).
constexpr double kMinRayAngleRad = 1.745e-4;
// Reciprocal condition of the Gauss-Newton normal matrix below which the point is not determined.
constexpr double kMinReciprocalCondition = 1e-12;
constexpr int kMaxGaussNewtonIterations = 50;

// The Gauss-Newton system of a point: the sum of squared reprojection residuals (px) and, when asked,
// J^T J and J^T r of the 2 x 3 Jacobians (analytic: the lens's own Jacobian, camera.h's Distort). False
// when the point is not in front of every camera or anything is not finite.
struct Normal {
  double cost = 0;
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
};
bool Reproject(const CameraIntrinsics& camera, double fx_px, const std::vector<Rigid3>& cam_from_base,
               const PointTrack& track, const Eigen::Vector3d& point, bool jacobian, Normal* out) {
  *out = Normal();
  const double fy_px = fx_px * camera.mu;
  for (size_t k = 0; k < cam_from_base.size(); ++k) {
    const Eigen::Vector3d p = cam_from_base[k] * point;
    if (!(p.z() > 0)) return false;
    const double inv_z = 1.0 / p.z();
    const Eigen::Vector2d xy(p.x() * inv_z, p.y() * inv_z);
    Eigen::Matrix2d d_distort;
    const Eigen::Vector2d xy_d = Distort(camera, xy, jacobian ? &d_distort : nullptr);
    const Eigen::Vector2d r(fx_px * xy_d.x() + camera.cx_px - track.pixels[k].x(),
                            fy_px * xy_d.y() + camera.cy_px - track.pixels[k].y());
    out->cost += r.squaredNorm();
    if (!jacobian) continue;
    Eigen::Matrix<double, 2, 3> d_xy;
    d_xy << inv_z, 0, -xy.x() * inv_z, 0, inv_z, -xy.y() * inv_z;
    Eigen::Matrix<double, 2, 3> j = d_distort * d_xy * cam_from_base[k].rotation;
    j.row(0) *= fx_px;
    j.row(1) *= fy_px;
    out->jtj.noalias() += j.transpose() * j;
    out->jtr.noalias() += j.transpose() * r;
  }
  return std::isfinite(out->cost) && out->jtj.allFinite() && out->jtr.allFinite();
}

}  // namespace

std::vector<Eigen::Vector3d> ScaleByNominalRatios(const std::vector<Eigen::Vector3d>& directions,
                                                  const std::vector<Eigen::Vector3d>& nominal_translations, double k1) {
  SELFCAL_CHECK(directions.size() == nominal_translations.size(),
                directions.size() << " directions but " << nominal_translations.size() << " nominal translations");
  SELFCAL_CHECK(!directions.empty(), "no pose measurements to scale");
  const double first = nominal_translations[0].norm();
  SELFCAL_CHECK(std::isfinite(first) && first > 0, "the first nominal translation has zero length: eq. (21) needs it");
  std::vector<Eigen::Vector3d> scaled(directions.size());
  for (size_t i = 0; i < directions.size(); ++i) {
    const double norm = directions[i].norm();
    SELFCAL_CHECK(norm > 0, "direction " << i << " is zero");
    scaled[i] = (nominal_translations[i].norm() / first) * k1 * (directions[i] / norm);
  }
  return scaled;
}

TriangulationResult TriangulatePoint(const CameraIntrinsics& camera, double fx_px, const PointTrack& track,
                                     double sigma_px) {
  SELFCAL_CHECK(track.base_from_cam.size() == track.pixels.size(),
                track.base_from_cam.size() << " camera poses but " << track.pixels.size() << " pixels");
  TriangulationResult result;
  const int num_views = static_cast<int>(track.pixels.size());
  if (num_views < 2) {
    result.message = "point seen in " + std::to_string(num_views) + " view(s), triangulation needs 2";
    return result;
  }
  if (!(std::isfinite(fx_px) && fx_px > 0) || !(sigma_px >= 0)) {
    result.message = "fx_px and sigma_px must be positive";
    return result;
  }
  std::vector<Rigid3> cam_from_base;
  std::vector<Eigen::Vector3d> rays(num_views);
  for (int k = 0; k < num_views; ++k) {
    cam_from_base.push_back(track.base_from_cam[k].Inverse());
    const Eigen::Vector2d xy = PixelToNormalized(camera, fx_px, track.pixels[k]);
    rays[k] = (track.base_from_cam[k].rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
  }
  // Depth is unobservable when all viewing lines are parallel (including opposite directions). The first
  // pair at or above the limit settles it (usually among the first few: O(views), not O(views^2)); only a
  // refusal looks at every pair, for the largest angle it names.
  double max_angle = 0;
  for (int a = 0; a < num_views && !(max_angle >= kMinRayAngleRad); ++a) {
    for (int b = a + 1; b < num_views && !(max_angle >= kMinRayAngleRad); ++b) {
      max_angle = std::max(max_angle, std::atan2(rays[a].cross(rays[b]).norm(), std::abs(rays[a].dot(rays[b]))));
    }
  }
  if (!(max_angle >= kMinRayAngleRad)) {
    std::ostringstream out;
    out << "ill-conditioned ray configuration: the viewing rays are within " << RadToDeg(max_angle)
        << " deg of parallel";
    result.message = out.str();
    return result;
  }

  // DLT on normalised coordinates: x (P3 X) - P1 X = 0, y (P3 X) - P2 X = 0; the null vector of the rows
  // as the smallest eigenvector of their 4 x 4 Gram matrix.
  Eigen::Matrix4d gram = Eigen::Matrix4d::Zero();
  for (int k = 0; k < num_views; ++k) {
    Eigen::Matrix<double, 3, 4> p;
    p << cam_from_base[k].rotation, cam_from_base[k].translation;
    const Eigen::Vector2d xy = PixelToNormalized(camera, fx_px, track.pixels[k]);
    const Eigen::Vector4d row_x = (xy.x() * p.row(2) - p.row(0)).transpose();
    const Eigen::Vector4d row_y = (xy.y() * p.row(2) - p.row(1)).transpose();
    gram.noalias() += row_x * row_x.transpose() + row_y * row_y.transpose();
  }
  const Eigen::Vector4d h = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(gram).eigenvectors().col(0);
  if (!(std::abs(h[3]) > 1e-12 * h.head<3>().norm())) {
    result.message = "the linear solution lies at infinity";
    return result;
  }
  Eigen::Vector3d point = h.head<3>() / h[3];
  for (int k = 0; k < num_views; ++k) {
    if (!((cam_from_base[k] * point).z() > 0)) {
      result.message = "the point lies behind camera " + std::to_string(k);
      return result;
    }
  }

  // Gauss-Newton on the reprojection error, halving steps that do not decrease it.
  Normal normal;
  if (!Reproject(camera, fx_px, cam_from_base, track, point, true, &normal)) {
    result.message = "non-finite reprojection at the linear solution";
    return result;
  }
  for (int iter = 0; iter < kMaxGaussNewtonIterations; ++iter) {
    const Eigen::Vector3d step = normal.jtj.ldlt().solve(-normal.jtr);
    if (!step.allFinite()) break;
    bool accepted = false;
    double scale = 1.0;
    for (int halving = 0; halving < 20 && !accepted; ++halving, scale *= 0.5) {
      const Eigen::Vector3d candidate = point + scale * step;
      Normal trial;
      // The Jacobian only for a candidate that is taken (and must be finite to be taken).
      if (Reproject(camera, fx_px, cam_from_base, track, candidate, false, &trial) && trial.cost <= normal.cost &&
          Reproject(camera, fx_px, cam_from_base, track, candidate, true, &trial)) {
        point = candidate;
        normal = trial;
        accepted = true;
      }
    }
    if (!accepted || scale * step.norm() <= 1e-15 * (1.0 + point.norm())) break;
  }

  const Eigen::Vector3d eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normal.jtj).eigenvalues();
  if (!(eig[0] > kMinReciprocalCondition * eig[2])) {
    result.message = "ill-conditioned ray configuration: the normal matrix is singular";
    return result;
  }
  result.ok = true;
  result.message = "ok";
  result.point = point;
  result.covariance = sigma_px * sigma_px * normal.jtj.inverse();
  result.rms_reprojection_px = std::sqrt(normal.cost / num_views);
  return result;
}

ScaleEstimate EstimateYardstickScale(const CameraIntrinsics& camera, double fx_px,
                                     const std::vector<YardstickView>& yardsticks, double sigma_px,
                                     double max_relative_sigma) {
  ScaleEstimate estimate;
  if (yardsticks.empty()) {
    estimate.message = "no yardstick measurements";
    return estimate;
  }
  if (!(std::isfinite(sigma_px) && sigma_px > 0)) {
    estimate.message = "sigma_px must be finite and > 0 to weight the yardsticks";
    return estimate;
  }
  double sum_wll = 0, sum_wLl = 0;
  std::vector<double> weights;
  for (size_t j = 0; j < yardsticks.size(); ++j) {
    const YardstickView& y = yardsticks[j];
    const std::string name = "yardstick " + std::to_string(j);
    if (!(std::isfinite(y.length_m) && y.length_m > 0)) {
      estimate.message = name + ": length " + std::to_string(y.length_m) + " m must be positive";
      return estimate;
    }
    for (const PointTrack* end : {&y.end_a, &y.end_b}) {
      if (end->pixels.size() < 2) {
        estimate.message = name + ": end " + (end == &y.end_a ? "a" : "b") + " seen in " +
                           std::to_string(end->pixels.size()) + " view(s), need 2";
        return estimate;
      }
    }
    const TriangulationResult a = TriangulatePoint(camera, fx_px, y.end_a, sigma_px);
    const TriangulationResult b = TriangulatePoint(camera, fx_px, y.end_b, sigma_px);
    if (!a.ok || !b.ok) {
      estimate.message = name + ": end " + (a.ok ? "b" : "a") + " not triangulated: " + (a.ok ? b.message : a.message);
      return estimate;
    }
    const Eigen::Vector3d stick = a.point - b.point;
    const double l = stick.norm();
    if (!(l > 0)) {
      estimate.message = name + ": both ends triangulate to the same point";
      return estimate;
    }
    const Eigen::Vector3d u = stick / l;
    // The two ends are triangulated independently: their covariances add along the stick.
    const double var = u.dot((a.covariance + b.covariance) * u);
    if (!(var > 0)) {
      estimate.message = name + ": zero length variance";
      return estimate;
    }
    const double w = 1.0 / var;
    weights.push_back(w);
    estimate.measured_lengths_m.push_back(l);
    estimate.per_yardstick_scale.push_back(y.length_m / l);
    sum_wll += w * l * l;
    sum_wLl += w * y.length_m * l;
  }
  const double s = sum_wLl / sum_wll;
  // First order: ds/dl_j = w_j (L_j - 2 s l_j) / sum(w l^2), var(l_j) = 1 / w_j.
  double var_s = 0;
  for (size_t j = 0; j < yardsticks.size(); ++j) {
    const double l = estimate.measured_lengths_m[j];
    const double d = weights[j] * (yardsticks[j].length_m - 2 * s * l) / sum_wll;
    var_s += d * d / weights[j];
  }
  estimate.scale = s;
  estimate.scale_sigma = std::sqrt(var_s);
  const double relative = estimate.scale_sigma / s;
  if (!(relative <= max_relative_sigma)) {
    std::ostringstream out;
    out << "scale ill-conditioned: relative sigma " << relative << " exceeds " << max_relative_sigma;
    estimate.message = out.str();
    return estimate;
  }
  estimate.ok = true;
  estimate.message = "ok";
  return estimate;
}

}  // namespace selfcal::identification
