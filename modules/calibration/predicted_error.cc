#include "calibration/predicted_error.h"

#include <cmath>
#include <sstream>

#include "identification/triangulation.h"

namespace selfcal::calibration {

namespace {

// Steps: large enough that the triangulation's convergence (it compares costs, so it stops within ~1e-10 m
// of the minimum) stays far below the difference, small enough that the curvature does not matter
// (relative truncation error ~h^2, below 1e-6 here).
constexpr double kRhoStep = 1e-4;    // m or rad
constexpr double kFxStep = 0.1;      // px
constexpr double kPixelStep = 0.05;  // px

// One end of a distance: the verification views that see the dot (index into pose_indices) and the pixel.
struct EndViews {
  std::vector<int> views;
  std::vector<Eigen::Vector2d> pixels;
};

EndViews Views(const ObservationSet& obs, const std::vector<int>& pose_indices, int dot) {
  EndViews end;
  for (size_t k = 0; k < pose_indices.size(); ++k) {
    const auto& dots = obs.poses[pose_indices[k]].dots_px;
    auto it = dots.find(dot);
    if (it == dots.end()) continue;
    end.views.push_back(static_cast<int>(k));
    end.pixels.push_back(it->second);
  }
  return end;
}

// Triangulates one end exactly as VerifyDistances does (sigma only scales the unused covariance).
bool Triangulate(const ObservationSet& obs, double fx_px, const std::vector<Rigid3>& cams, const EndViews& end,
                 const std::vector<Eigen::Vector2d>& pixels, Eigen::Vector3d* point) {
  identification::PointTrack track;
  for (size_t k = 0; k < end.views.size(); ++k) {
    track.base_from_cam.push_back(cams[end.views[k]]);
    track.pixels.push_back(pixels[k]);
  }
  const identification::TriangulationResult r = identification::TriangulatePoint(obs.camera, fx_px, track, 1.0);
  if (!r.ok) return false;
  *point = r.point;
  return true;
}

// The ends of every distance and which distances still triangulate (false where a triangulation failed).
struct Ends {
  std::vector<EndViews> a, b;
  std::vector<bool> ok;
};

// The camera poses of the given poses at a model.
std::vector<Rigid3> Cameras(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                            const Eigen::VectorXd& rho) {
  std::vector<Rigid3> cams;
  for (int p : pose_indices) cams.push_back(BaseFromCamAt(robot, rho, obs.poses[p]));
  return cams;
}

// What is wrong with the inputs, one line each; empty when they are valid.
std::string CheckInputs(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                        const Eigen::VectorXd& rho, double fx_px, const std::vector<int>& free_indices,
                        const Eigen::MatrixXd& covariance, double sigma_px, double step_scale) {
  const int nt = static_cast<int>(free_indices.size()) + 1;
  std::ostringstream problems;
  if (rho.size() != robot.num_parameters() || !rho.allFinite()) problems << "rho must be finite with " << robot.num_parameters() << " entries\n";
  for (int i : free_indices) {
    if (i < 0 || i >= rho.size()) problems << "free index " << i << " out of range\n";
  }
  if (!(std::isfinite(fx_px) && fx_px > 0)) problems << "f_x must be finite and > 0\n";
  if (covariance.rows() < nt || covariance.cols() != covariance.rows() || !covariance.allFinite()) {
    problems << "covariance must be square, finite, with at least free + 1 (f_x) = " << nt << " rows\n";
  }
  if (!(std::isfinite(sigma_px) && sigma_px >= 0)) problems << "sigma_px must be finite and >= 0\n";
  if (!(std::isfinite(step_scale) && step_scale > 0)) problems << "step_scale must be > 0\n";
  for (int p : pose_indices) {
    if (p < 0 || p >= static_cast<int>(obs.poses.size())) problems << "pose index " << p << " out of range\n";
  }
  return problems.str();
}

// Both ends' views of every distance and the distance at the model (cams0, fx_px); out->distances gets
// the known distance, the measured one and zero gradients of their sizes (nt parameters).
Ends MeasureAtModel(const ObservationSet& obs, const std::vector<int>& pose_indices, double fx_px,
                    const std::vector<Rigid3>& cams0, const std::vector<KnownDistance>& distances, int nt,
                    PredictedDistanceErrors* out) {
  const size_t nd = distances.size();
  Ends ends;
  ends.a.resize(nd);
  ends.b.resize(nd);
  out->distances.resize(nd);
  ends.ok.assign(nd, true);
  for (size_t d = 0; d < nd; ++d) {
    PredictedDistanceError& e = out->distances[d];
    e.known = distances[d];
    ends.a[d] = Views(obs, pose_indices, distances[d].dot_a);
    ends.b[d] = Views(obs, pose_indices, distances[d].dot_b);
    e.gradient_theta = Eigen::VectorXd::Zero(nt);
    e.gradient_px = Eigen::VectorXd::Zero(2 * (ends.a[d].views.size() + ends.b[d].views.size()));
    Eigen::Vector3d a, b;
    ends.ok[d] = Triangulate(obs, fx_px, cams0, ends.a[d], ends.a[d].pixels, &a) &&
                 Triangulate(obs, fx_px, cams0, ends.b[d], ends.b[d].pixels, &b);
    if (ends.ok[d]) e.measured_m = (a - b).norm();
  }
  return ends;
}

// Distance of every check at a model; false entries of ends->ok where a triangulation failed.
void AllDistances(const ObservationSet& obs, const std::vector<Rigid3>& cams, double fx, Ends* ends,
                  std::vector<double>* values) {
  const size_t nd = ends->ok.size();
  values->assign(nd, 0.0);
  for (size_t d = 0; d < nd; ++d) {
    if (!ends->ok[d]) continue;
    Eigen::Vector3d a, b;
    if (Triangulate(obs, fx, cams, ends->a[d], ends->a[d].pixels, &a) &&
        Triangulate(obs, fx, cams, ends->b[d], ends->b[d].pixels, &b)) {
      (*values)[d] = (a - b).norm();
    } else {
      ends->ok[d] = false;
    }
  }
}

// g_theta: one pair of model evaluations per parameter (free entries of rho, then f_x), shared by every
// distance.
void ParameterGradients(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                        const Eigen::VectorXd& rho, double fx_px, const std::vector<int>& free_indices,
                        double step_scale, const std::vector<Rigid3>& cams0, Ends* ends,
                        PredictedDistanceErrors* out) {
  const int nf = static_cast<int>(free_indices.size());
  const int nt = nf + 1;
  std::vector<double> plus, minus;
  for (int t = 0; t < nt; ++t) {
    const bool is_fx = t == nf;
    const double h = step_scale * (is_fx ? kFxStep : kRhoStep);
    Eigen::VectorXd r = rho;
    if (is_fx) {
      AllDistances(obs, cams0, fx_px + h, ends, &plus);
      AllDistances(obs, cams0, fx_px - h, ends, &minus);
    } else {
      r[free_indices[t]] = rho[free_indices[t]] + h;
      AllDistances(obs, Cameras(obs, pose_indices, robot, r), fx_px, ends, &plus);
      r[free_indices[t]] = rho[free_indices[t]] - h;
      AllDistances(obs, Cameras(obs, pose_indices, robot, r), fx_px, ends, &minus);
    }
    for (size_t d = 0; d < ends->ok.size(); ++d) out->distances[d].gradient_theta[t] = (plus[d] - minus[d]) / (2 * h);
  }
}

// g_px of distance d: only the perturbed end moves (pixel step hp). False when a perturbed end does not
// triangulate.
bool PixelGradient(const ObservationSet& obs, double fx_px, const std::vector<Rigid3>& cams0, double hp,
                   const EndViews& end_a, const EndViews& end_b, PredictedDistanceError* e) {
  Eigen::Vector3d a0, b0;
  Triangulate(obs, fx_px, cams0, end_a, end_a.pixels, &a0);
  Triangulate(obs, fx_px, cams0, end_b, end_b.pixels, &b0);
  int row = 0;
  for (int end = 0; end < 2; ++end) {
    const EndViews& v = end == 0 ? end_a : end_b;
    const Eigen::Vector3d& other = end == 0 ? b0 : a0;
    for (size_t k = 0; k < v.views.size(); ++k) {
      for (int c = 0; c < 2; ++c, ++row) {
        std::vector<Eigen::Vector2d> pixels = v.pixels;
        Eigen::Vector3d p_plus, p_minus;
        pixels[k][c] = v.pixels[k][c] + hp;
        const bool ok_plus = Triangulate(obs, fx_px, cams0, v, pixels, &p_plus);
        pixels[k][c] = v.pixels[k][c] - hp;
        const bool ok_minus = Triangulate(obs, fx_px, cams0, v, pixels, &p_minus);
        if (!ok_plus || !ok_minus) return false;
        e->gradient_px[row] = ((p_plus - other).norm() - (p_minus - other).norm()) / (2 * hp);
      }
    }
  }
  return true;
}

// The variances of every distance that is ok and their quadratic means.
void CombineVariances(const Eigen::MatrixXd& sigma, double sigma_px, const std::vector<bool>& ok,
                      PredictedDistanceErrors* out) {
  double sum2 = 0, sum2_a = 0, sum2_b = 0;
  for (size_t d = 0; d < ok.size(); ++d) {
    PredictedDistanceError& e = out->distances[d];
    e.ok = ok[d];
    if (!e.ok) continue;
    const double var_a = std::max(0.0, e.gradient_theta.dot(sigma * e.gradient_theta));
    const double var_b = sigma_px * sigma_px * e.gradient_px.squaredNorm();
    e.parameters_std_m = std::sqrt(var_a);
    e.pixels_std_m = std::sqrt(var_b);
    e.std_m = std::sqrt(var_a + var_b);
    ++out->num_ok;
    sum2 += var_a + var_b;
    sum2_a += var_a;
    sum2_b += var_b;
  }
  if (out->num_ok > 0) {
    out->rms_std_m = std::sqrt(sum2 / out->num_ok);
    out->rms_parameters_std_m = std::sqrt(sum2_a / out->num_ok);
    out->rms_pixels_std_m = std::sqrt(sum2_b / out->num_ok);
    out->ok = true;
    out->message = "ok";
  } else {
    out->message = "no check distance triangulated from the given poses";
  }
}

}  // namespace

PredictedDistanceErrors PredictDistanceErrors(const ObservationSet& obs, const std::vector<int>& pose_indices,
                                              const RobotModel& robot, const Eigen::VectorXd& rho, double fx_px,
                                              const std::vector<int>& free_indices, const Eigen::MatrixXd& covariance,
                                              double sigma_px, const std::vector<KnownDistance>& distances,
                                              double step_scale) {
  PredictedDistanceErrors out;
  const int nt = static_cast<int>(free_indices.size()) + 1;
  const std::string problems =
      CheckInputs(obs, pose_indices, robot, rho, fx_px, free_indices, covariance, sigma_px, step_scale);
  if (!problems.empty()) {
    out.message = problems;
    return out;
  }
  const Eigen::MatrixXd sigma = covariance.topLeftCorner(nt, nt);
  const std::vector<Rigid3> cams0 = Cameras(obs, pose_indices, robot, rho);
  Ends ends = MeasureAtModel(obs, pose_indices, fx_px, cams0, distances, nt, &out);
  ParameterGradients(obs, pose_indices, robot, rho, fx_px, free_indices, step_scale, cams0, &ends, &out);
  const double hp = step_scale * kPixelStep;
  for (size_t d = 0; d < distances.size(); ++d) {
    if (!ends.ok[d]) continue;
    ends.ok[d] = PixelGradient(obs, fx_px, cams0, hp, ends.a[d], ends.b[d], &out.distances[d]);
  }
  CombineVariances(sigma, sigma_px, ends.ok, &out);
  return out;
}

}  // namespace selfcal::calibration
