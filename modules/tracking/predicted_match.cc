#include "tracking/predicted_match.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "tracking/planar_fit.h"

namespace selfcal::tracking {
namespace {

constexpr double kMedianChi2TwoDof = 1.3862943611198906;  // 2 ln 2

double UpperMedian(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

// The model scatter (isotropic) from the residuals of the inliers of a fit with `params` parameters.
double ModelVariance(const std::vector<double>& squared_residuals, int params, const PredictionCorrectionOptions& o) {
  const int n = static_cast<int>(squared_residuals.size());
  double var = o.fallback_model_sigma_px * o.fallback_model_sigma_px;
  if (n >= params + 3) {
    var = UpperMedian(squared_residuals) / kMedianChi2TwoDof * static_cast<double>(2 * n) / static_cast<double>(2 * n - params);
  }
  return std::max(var, o.min_model_sigma_px * o.min_model_sigma_px);
}

}  // namespace

PredictedDot PredictionCorrection::Apply(const PredictedDot& p) const {
  PredictedDot out = p;
  out.uv_px = MapPoint(observed_from_predicted, p.uv_px);
  const Eigen::Matrix2d a = observed_from_predicted.topLeftCorner<2, 2>() / observed_from_predicted(2, 2);
  out.cov_px2 = a * p.cov_px2 * a.transpose() + model_cov_px2;
  return out;
}

PredictionCorrection FitPredictionCorrection(const std::vector<Eigen::Vector2d>& predicted,
                                             const std::vector<Eigen::Vector2d>& observed,
                                             const PredictionCorrectionOptions& options) {
  PredictionCorrection c;
  const size_t n = std::min(predicted.size(), observed.size());
  c.anchors = static_cast<int>(n);
  if (n == 0) {
    c.message = "no anchor";
    return c;
  }
  // A robust translation first: the component-wise median offset and the anchors that agree with it.
  std::vector<double> du, dv;
  for (size_t k = 0; k < n; ++k) {
    du.push_back(observed[k].x() - predicted[k].x());
    dv.push_back(observed[k].y() - predicted[k].y());
  }
  Eigen::Vector2d t(UpperMedian(du), UpperMedian(dv));
  std::vector<size_t> in;
  for (size_t k = 0; k < n; ++k) {
    if ((observed[k] - predicted[k] - t).norm() <= options.inlier_threshold_px) in.push_back(k);
  }
  if (in.empty()) {
    c.message = "the anchors agree on no offset";
    return c;
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (size_t k : in) mean += observed[k] - predicted[k];
  t = mean / static_cast<double>(in.size());
  c.observed_from_predicted.topRightCorner<2, 1>() = t;
  int params = 2;
  if (static_cast<int>(in.size()) >= options.min_anchors_affine) {
    RobustPlanarFitOptions fit_options;
    fit_options.model = PlanarModel::kAffine;
    fit_options.inlier_threshold = options.inlier_threshold_px;
    fit_options.seed = options.seed;
    const RobustPlanarFit fit = FitPlanarRobust(fit_options, predicted, observed);
    if (fit.ok && fit.inlier_count >= static_cast<int>(in.size())) {
      c.observed_from_predicted = fit.to_from_from;
      params = 6;
      in.clear();
      for (size_t k = 0; k < n; ++k) {
        if (fit.inliers[k]) in.push_back(k);
      }
    }
  }
  std::vector<double> squared;
  for (size_t k : in) squared.push_back((MapPoint(c.observed_from_predicted, predicted[k]) - observed[k]).squaredNorm());
  c.inliers = static_cast<int>(in.size());
  if (2 * c.inliers < c.anchors) {
    std::ostringstream s;
    s << "only " << c.inliers << " of " << c.anchors << " anchors agree";
    c.message = s.str();
    return c;
  }
  const double var = ModelVariance(squared, params, options);
  c.model_cov_px2 = var * Eigen::Matrix2d::Identity();
  std::ostringstream s;
  s << (params == 6 ? "affine" : "translation") << " from " << c.inliers << " of " << c.anchors
    << " anchors, scatter " << std::sqrt(var) << " px";
  c.message = s.str();
  c.ok = true;
  return c;
}

PredictionCorrection VotePredictionCorrection(const std::vector<PredictedDot>& predictions,
                                              const std::vector<Eigen::Vector2d>& detections,
                                              const PredictionCorrectionOptions& options) {
  PredictionCorrection none;
  const double r2 = options.vote_radius_px * options.vote_radius_px;
  // The detection nearest to p within the vote radius, or -1.
  auto near = [&](const Eigen::Vector2d& p) {
    int best = -1;
    double best_d2 = r2;
    for (size_t k = 0; k < detections.size(); ++k) {
      const double d2 = (detections[k] - p).squaredNorm();
      if (d2 <= best_d2) {
        best_d2 = d2;
        best = static_cast<int>(k);
      }
    }
    return best;
  };
  auto support = [&](const Eigen::Vector2d& t) {
    int count = 0;
    for (const PredictedDot& q : predictions) count += near(q.uv_px + t) >= 0 ? 1 : 0;
    return count;
  };
  std::vector<std::pair<int, Eigen::Vector2d>> votes;
  for (const PredictedDot& p : predictions) {
    for (const Eigen::Vector2d& d : detections) {
      const Eigen::Vector2d t = d - p.uv_px;
      if (t.norm() <= options.vote_search_px) votes.push_back({support(t), t});
    }
  }
  if (votes.empty()) {
    none.message = "no detection near any prediction";
    return none;
  }
  auto best = std::max_element(votes.begin(), votes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  int second = 0;
  for (const auto& [s, t] : votes) {
    if ((t - best->second).norm() > 2 * options.vote_radius_px) second = std::max(second, s);
  }
  const int possible = static_cast<int>(std::min(predictions.size(), detections.size()));
  std::ostringstream why;
  why << "best translation supported by " << best->first << " dots of " << possible << ", the next by " << second;
  if (best->first < options.min_vote_support || best->first < options.min_vote_fraction * possible ||
      2 * second > best->first) {
    none.message = why.str();
    return none;
  }
  std::vector<Eigen::Vector2d> from, to;
  for (const PredictedDot& q : predictions) {
    const int k = near(q.uv_px + best->second);
    if (k >= 0) {
      from.push_back(q.uv_px);
      to.push_back(detections[static_cast<size_t>(k)]);
    }
  }
  PredictionCorrection c = FitPredictionCorrection(from, to, options);
  c.from_votes = true;
  c.message = why.str() + "; " + c.message;
  return c;
}

double Mahalanobis2(const PredictedDot& prediction, const Eigen::Vector2d& uv_px) {
  const Eigen::Matrix2d& s = prediction.cov_px2;
  const double det = s.determinant();
  if (!(det > 0) || !std::isfinite(det)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d r = uv_px - prediction.uv_px;
  return r.dot(s.inverse() * r);
}

PredictedMatch MatchPredictions(const std::vector<PredictedDot>& predictions,
                                const std::vector<Eigen::Vector2d>& detections, const PredictedMatchOptions& options) {
  PredictedMatch m;
  m.id_of_detection.assign(detections.size(), -1);
  m.gates_of_detection.assign(detections.size(), 0);
  std::vector<int> detections_in_gate(predictions.size(), 0);
  std::vector<std::vector<size_t>> gates_holding(detections.size());
  for (size_t k = 0; k < detections.size(); ++k) {
    for (size_t j = 0; j < predictions.size(); ++j) {
      if (Mahalanobis2(predictions[j], detections[k]) <= options.gate_chi2) {
        gates_holding[k].push_back(j);
        ++detections_in_gate[j];
      }
    }
  }
  for (size_t k = 0; k < detections.size(); ++k) {
    // The dots whose gates hold the detection, and the gate that may name it.
    int naming = -1;
    std::vector<int> ids;
    for (size_t j : gates_holding[k]) {
      ids.push_back(predictions[j].id);
      if (predictions[j].names && naming < 0) naming = static_cast<int>(j);
    }
    std::sort(ids.begin(), ids.end());
    const int dots = static_cast<int>(std::unique(ids.begin(), ids.end()) - ids.begin());
    m.gates_of_detection[k] = dots;
    if (dots == 0) {
      ++m.outside_gates;
    } else if (dots == 1 && naming >= 0 && detections_in_gate[static_cast<size_t>(naming)] == 1) {
      m.id_of_detection[k] = predictions[static_cast<size_t>(naming)].id;
      ++m.named;
    } else {
      ++m.ambiguous;
    }
  }
  return m;
}

}  // namespace selfcal::tracking
