#include "tracking/planar_fit.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <Eigen/Dense>
#include <Eigen/SVD>

namespace selfcal::tracking {
namespace {

// Similarity T with T p = (p - centroid) * sqrt(2) / mean distance (Hartley normalisation).
std::optional<Eigen::Matrix3d> Normalizer(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  double mean = 0;
  for (const auto& p : pts) mean += (p - c).norm();
  mean /= static_cast<double>(pts.size());
  if (!(mean > 0) || !std::isfinite(mean)) return std::nullopt;
  const double s = std::sqrt(2.0) / mean;
  Eigen::Matrix3d t;
  t << s, 0, -s * c.x(), 0, s, -s * c.y(), 0, 0, 1;
  return t;
}

bool AllFinite(const std::vector<Eigen::Vector2d>& pts) {
  return std::all_of(pts.begin(), pts.end(), [](const Eigen::Vector2d& p) { return p.allFinite(); });
}

// Twice the signed area of the triangle.
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

std::optional<Eigen::Matrix3d> Fit(PlanarModel model, const std::vector<Eigen::Vector2d>& from,
                                   const std::vector<Eigen::Vector2d>& to) {
  return model == PlanarModel::kHomography ? FitHomography(from, to) : FitAffine(from, to);
}

}  // namespace

Eigen::Vector2d MapPoint(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = h * p.homogeneous();
  if (!(std::abs(q.z()) >= 1e-12)) return Eigen::Vector2d::Constant(std::nan(""));
  return q.hnormalized();
}

std::optional<Eigen::Matrix3d> FitHomography(const std::vector<Eigen::Vector2d>& from,
                                             const std::vector<Eigen::Vector2d>& to) {
  if (from.size() != to.size() || from.size() < 4 || !AllFinite(from) || !AllFinite(to)) return std::nullopt;
  const auto t_from = Normalizer(from);
  const auto t_to = Normalizer(to);
  if (!t_from || !t_to) return std::nullopt;
  const int n = static_cast<int>(from.size());
  Eigen::MatrixXd a(2 * n, 9);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = *t_from * from[static_cast<size_t>(i)].homogeneous();
    const Eigen::Vector3d y = *t_to * to[static_cast<size_t>(i)].homogeneous();
    a.row(2 * i) << 0, 0, 0, -x.transpose(), y.y() * x.transpose();
    a.row(2 * i + 1) << x.transpose(), 0, 0, 0, -y.x() * x.transpose();
  }
  // The null vector of A; with exactly 4 points A is 8x9, so pad to get the full V from the SVD.
  Eigen::MatrixXd ata = a.transpose() * a;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(ata);
  if (eig.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix<double, 9, 1> values = eig.eigenvalues();  // ascending
  // Degenerate configurations leave a second (near-)null direction.
  if (!(values(1) > 1e-10 * std::max(1.0, values(8)))) return std::nullopt;
  const Eigen::Matrix<double, 9, 1> hv = eig.eigenvectors().col(0);
  Eigen::Matrix3d hn;
  hn << hv(0), hv(1), hv(2), hv(3), hv(4), hv(5), hv(6), hv(7), hv(8);
  Eigen::Matrix3d h = t_to->inverse() * hn * *t_from;
  if (!h.allFinite()) return std::nullopt;
  if (std::abs(h(2, 2)) > 1e-12 * h.norm()) {
    h /= h(2, 2);
  } else {
    h /= h.norm();
  }
  return h;
}

std::optional<Eigen::Matrix3d> FitAffine(const std::vector<Eigen::Vector2d>& from,
                                         const std::vector<Eigen::Vector2d>& to) {
  if (from.size() != to.size() || from.size() < 3 || !AllFinite(from) || !AllFinite(to)) return std::nullopt;
  const auto t_from = Normalizer(from);
  const auto t_to = Normalizer(to);
  if (!t_from || !t_to) return std::nullopt;
  const int n = static_cast<int>(from.size());
  Eigen::MatrixXd a(n, 3);
  Eigen::MatrixXd b(n, 2);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = *t_from * from[static_cast<size_t>(i)].homogeneous();
    const Eigen::Vector3d y = *t_to * to[static_cast<size_t>(i)].homogeneous();
    a.row(i) << x.x(), x.y(), 1.0;
    b.row(i) << y.x(), y.y();
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv(2) > 1e-8 * sv(0))) return std::nullopt;  // collinear
  const Eigen::MatrixXd x = svd.solve(b);             // 3x2
  Eigen::Matrix3d an = Eigen::Matrix3d::Identity();
  an.block<2, 3>(0, 0) = x.transpose();
  Eigen::Matrix3d m = t_to->inverse() * an * *t_from;
  m.row(2) << 0, 0, 1;
  if (!m.allFinite()) return std::nullopt;
  return m;
}

const char* PlanarModelName(PlanarModel model) {
  return model == PlanarModel::kHomography ? "homography" : "affine";
}

Status RobustPlanarFitOptions::Validate() const {
  std::ostringstream s;
  if (!(inlier_threshold > 0)) s << "inlier_threshold must be > 0, got " << inlier_threshold << "\n";
  if (iterations < 1) s << "iterations must be >= 1, got " << iterations << "\n";
  if (!(confidence > 0 && confidence < 1)) s << "confidence must be in (0, 1), got " << confidence << "\n";
  if (!(min_inlier_fraction >= 0 && min_inlier_fraction <= 1)) {
    s << "min_inlier_fraction must be in [0, 1], got " << min_inlier_fraction << "\n";
  }
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

RobustPlanarFit FitPlanarRobust(const RobustPlanarFitOptions& options, const std::vector<Eigen::Vector2d>& from,
                                const std::vector<Eigen::Vector2d>& to) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid RobustPlanarFitOptions:\n" << valid.message());
  SELFCAL_CHECK(from.size() == to.size(), "point sets differ in size: " << from.size() << " vs " << to.size());
  RobustPlanarFit fit;
  const size_t n = from.size();
  const size_t sample_size = options.model == PlanarModel::kHomography ? 4 : 3;
  if (n < sample_size) {
    std::ostringstream s;
    s << PlanarModelName(options.model) << " needs " << sample_size << " correspondences, got " << n;
    fit.message = s.str();
    return fit;
  }
  auto score = [&](const Eigen::Matrix3d& h, std::vector<double>* residuals, std::vector<bool>* inliers) {
    residuals->assign(n, std::nan(""));
    inliers->assign(n, false);
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      const double r = (MapPoint(h, from[i]) - to[i]).norm();
      (*residuals)[i] = r;
      if (r <= options.inlier_threshold) {
        (*inliers)[i] = true;
        ++count;
      }
    }
    return count;
  };

  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  int best_count = -1;
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  std::vector<double> residuals;
  std::vector<bool> inliers;
  std::vector<Eigen::Vector2d> sf(sample_size), st(sample_size);
  int needed = options.iterations;
  for (int it = 0; it < std::min(needed, options.iterations); ++it) {
    std::vector<size_t> idx;
    while (idx.size() < sample_size) {
      const size_t k = pick(rng);
      if (std::find(idx.begin(), idx.end(), k) == idx.end()) idx.push_back(k);
    }
    for (size_t k = 0; k < sample_size; ++k) {
      sf[k] = from[idx[k]];
      st[k] = to[idx[k]];
    }
    // Skip samples with three (nearly) collinear points in either set.
    bool degenerate = false;
    for (size_t a = 0; a < sample_size && !degenerate; ++a) {
      for (size_t b = a + 1; b < sample_size && !degenerate; ++b) {
        for (size_t c = b + 1; c < sample_size && !degenerate; ++c) {
          const double scale_f = std::max({(sf[b] - sf[a]).squaredNorm(), (sf[c] - sf[a]).squaredNorm(), 1e-300});
          const double scale_t = std::max({(st[b] - st[a]).squaredNorm(), (st[c] - st[a]).squaredNorm(), 1e-300});
          degenerate = std::abs(Cross(sf[a], sf[b], sf[c])) < 1e-3 * scale_f ||
                       std::abs(Cross(st[a], st[b], st[c])) < 1e-3 * scale_t;
        }
      }
    }
    if (degenerate) continue;
    const auto h = Fit(options.model, sf, st);
    if (!h) continue;
    const int count = score(*h, &residuals, &inliers);
    if (count > best_count) {
      best_count = count;
      best = *h;
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double all_inliers = std::pow(w, static_cast<double>(sample_size));
      if (all_inliers >= 1.0) {
        needed = 0;
      } else if (all_inliers > 0) {
        needed = static_cast<int>(std::ceil(std::log(1.0 - options.confidence) / std::log(1.0 - all_inliers)));
      }
    }
  }
  if (best_count < 0) {
    fit.message = "every random sample was degenerate";
    return fit;
  }
  fit.to_from_from = best;
  fit.inlier_count = score(best, &fit.residuals, &fit.inliers);
  for (int refit = 0; refit < 2; ++refit) {
    std::vector<Eigen::Vector2d> in_from, in_to;
    for (size_t i = 0; i < n; ++i) {
      if (fit.inliers[i]) {
        in_from.push_back(from[i]);
        in_to.push_back(to[i]);
      }
    }
    const auto h = Fit(options.model, in_from, in_to);
    if (!h) break;
    std::vector<double> r;
    std::vector<bool> in;
    const int count = score(*h, &r, &in);
    if (count < fit.inlier_count) break;
    fit.to_from_from = *h;
    fit.residuals = r;
    fit.inliers = in;
    fit.inlier_count = count;
  }
  const double fraction = static_cast<double>(fit.inlier_count) / static_cast<double>(n);
  if (fraction < options.min_inlier_fraction) {
    std::ostringstream s;
    s << "only " << fit.inlier_count << " of " << n << " correspondences within " << options.inlier_threshold
      << " of the best " << PlanarModelName(options.model) << " (min fraction " << options.min_inlier_fraction << ")";
    fit.message = s.str();
    return fit;
  }
  fit.ok = true;
  return fit;
}

}  // namespace selfcal::tracking
