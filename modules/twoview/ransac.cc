// Classic RANSAC (G7, G8) for the fundamental matrix and the homography, and the ORB-SLAM2-style scores
// that choose between them (G4).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Dense>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {
namespace {

// 95 % quantiles of chi-square with 1 and 2 degrees of freedom: the gates of a 1-DOF residual (distance
// to an epipolar line) and a 2-DOF residual (homography transfer error) at the same noise level.
constexpr double kChi2OneDof = 3.841;
constexpr double kChi2TwoDof = 5.991;

// Iterations so that an all-inlier sample is drawn with the requested confidence (G7); the cap keeps a
// hopeless outlier ratio from running forever (G8).
int AdaptiveIterations(double inlier_ratio, int sample_size, double confidence, int cap) {
  const double all_inliers = std::pow(inlier_ratio, sample_size);
  if (all_inliers >= 1.0 - 1e-12) return 1;
  if (!(all_inliers > 0)) return cap;
  const double needed = std::ceil(std::log(1.0 - confidence) / std::log(1.0 - all_inliers));
  return static_cast<int>(std::min<double>(needed, cap));
}

// Draws `k` distinct indices into perm[0..k) by a partial Fisher-Yates shuffle of the running
// permutation; deterministic for a given generator state (P9).
void DrawSample(int k, std::vector<int>* perm, std::mt19937_64* rng, std::vector<int>* sample) {
  const int n = static_cast<int>(perm->size());
  for (int i = 0; i < k; ++i) {
    std::uniform_int_distribution<int> pick(i, n - 1);
    std::swap((*perm)[i], (*perm)[pick(*rng)]);
  }
  sample->assign(perm->begin(), perm->begin() + k);
}

// Per-correspondence squared residual of a model in pixels and its inlier gate (squared).
struct FundamentalResidual {
  Eigen::Matrix3d f_px;
  double operator()(const Correspondences& d, int i) const { return SampsonSquared(f_px, d.pixels1[i], d.pixels2[i]); }
};
struct HomographyResidual {
  Eigen::Matrix3d h_px, h_px_inv;
  double operator()(const Correspondences& d, int i) const {
    double e12 = 0, e21 = 0;
    TransferErrors(h_px, h_px_inv, d.pixels1[i], d.pixels2[i], &e12, &e21);
    return std::max(e12, e21);
  }
};

// Generic loop: MSAC objective (sum of squared residuals truncated at the gate), which prefers the
// tighter of two models with equal inlier counts; adaptive stopping on the inlier ratio of the best, or
// on useful_inlier_ratio if that is larger (a model explaining less would not be used anyway).
// Then the model is re-estimated on all its inliers and the inliers recomputed by us (G8: never trust
// the sample's inlier set), twice, keeping the re-estimate only if it does not lose inliers.
template <typename Fit, typename MakeResidual>
RansacResult RunRansac(const TwoViewOptions& options, const Correspondences& data, int sample_size, double gate_sq,
                       double useful_inlier_ratio, const Fit& fit, const MakeResidual& make_residual,
                       std::mt19937_64* rng) {
  RansacResult result;
  const int n = data.size();
  result.inliers.assign(n, false);
  if (n < sample_size) return result;
  std::vector<int> perm(n), sample;
  std::iota(perm.begin(), perm.end(), 0);
  double best_cost = std::numeric_limits<double>::infinity();
  int needed =
      AdaptiveIterations(useful_inlier_ratio, sample_size, options.ransac_confidence, options.ransac_max_iterations);
  // After this many degenerate samples in a row without any model, the whole set is tested once: if it
  // is degenerate (exactly planar for F, collinear for H), every subset is, and the loop would only burn
  // its iteration cap.
  constexpr int kDegenerateStreak = 20;
  int streak = 0;
  int it = 0;
  for (; it < needed && it < options.ransac_max_iterations; ++it) {
    DrawSample(sample_size, &perm, rng, &sample);
    Eigen::Matrix3d model;
    if (!fit(sample, &model)) {
      if (!result.found && ++streak == kDegenerateStreak && !fit(perm, &model)) {
        ++it;
        break;
      }
      continue;
    }
    const auto residual = make_residual(model);
    double cost = 0;
    int count = 0;
    for (int i = 0; i < n && cost < best_cost; ++i) {
      const double r = residual(data, i);
      if (r <= gate_sq) {
        cost += r;
        ++count;
      } else {
        cost += gate_sq;
      }
    }
    if (cost < best_cost) {
      best_cost = cost;
      result.found = true;
      result.model = model;
      needed = AdaptiveIterations(std::max(static_cast<double>(count) / n, useful_inlier_ratio), sample_size,
                                  options.ransac_confidence, options.ransac_max_iterations);
    }
  }
  result.iterations = it;
  if (!result.found) return result;

  auto inliers_of = [&](const Eigen::Matrix3d& model, std::vector<int>* indices) {
    const auto residual = make_residual(model);
    indices->clear();
    for (int i = 0; i < n; ++i) {
      if (residual(data, i) <= gate_sq) indices->push_back(i);
    }
  };
  std::vector<int> inliers;
  inliers_of(result.model, &inliers);
  for (int round = 0; round < 2; ++round) {
    Eigen::Matrix3d refit;
    if (static_cast<int>(inliers.size()) < sample_size || !fit(inliers, &refit)) break;
    std::vector<int> refit_inliers;
    inliers_of(refit, &refit_inliers);
    if (refit_inliers.size() < inliers.size()) break;
    result.model = refit;
    inliers.swap(refit_inliers);
  }
  for (int i : inliers) result.inliers[i] = true;
  result.num_inliers = static_cast<int>(inliers.size());
  return result;
}

}  // namespace

double HomographyThresholdPx(const TwoViewOptions& options) {
  // Same noise level as the Sampson gate, but a 2-DOF residual: scale by sqrt(chi2_2 / chi2_1).
  return options.ransac_threshold_px * std::sqrt(kChi2TwoDof / kChi2OneDof);
}

RansacResult RansacFundamental(const TwoViewOptions& options, const CameraIntrinsics& camera,
                               const Correspondences& data, std::mt19937_64* rng) {
  auto fit = [&](const std::vector<int>& indices, Eigen::Matrix3d* f) {
    return EightPoint(data.centred1, data.centred2, indices, f);
  };
  auto make_residual = [&](const Eigen::Matrix3d& f_centred) {
    return FundamentalResidual{FundamentalToPixels(camera, f_centred)};
  };
  const double gate = options.ransac_threshold_px;
  return RunRansac(options, data, 8, gate * gate, 0.0, fit, make_residual, rng);
}

RansacResult RansacHomography(const TwoViewOptions& options, const CameraIntrinsics& camera,
                              const Correspondences& data, double useful_inlier_ratio, std::mt19937_64* rng) {
  auto fit = [&](const std::vector<int>& indices, Eigen::Matrix3d* h) {
    return HomographyDlt(data.centred1, data.centred2, indices, h);
  };
  auto make_residual = [&](const Eigen::Matrix3d& h_centred) {
    const Eigen::Matrix3d h_px = HomographyToPixels(camera, h_centred);
    return HomographyResidual{h_px, h_px.inverse()};
  };
  const double gate = HomographyThresholdPx(options);
  return RunRansac(options, data, 4, gate * gate, useful_inlier_ratio, fit, make_residual, rng);
}

// Scores (ORB-SLAM2, Mur-Artal et al. 2015): per correspondence and per image, a residual inside its
// chi-square gate earns (gate - r^2 / sigma^2). sigma is set so that the 1-DOF gate equals
// ransac_threshold_px. Unlike ORB-SLAM2, which credits both residual kinds with the 2-DOF gate, each
// residual is credited with its own gate: otherwise a planar scene, which both models explain equally,
// gives R_H ~ 0.42 at the noise the threshold is made for and falls under the 0.45 switch. With own
// gates an exactly planar scene scores R_H ~ 0.55-0.6, a 3D scene stays near 0.
double FundamentalScore(const TwoViewOptions& options, const CameraIntrinsics& camera, const Eigen::Matrix3d& f_centred,
                        const Correspondences& data) {
  const double sigma_sq = options.ransac_threshold_px * options.ransac_threshold_px / kChi2OneDof;
  const Eigen::Matrix3d f_px = FundamentalToPixels(camera, f_centred);
  double score = 0;
  for (int i = 0; i < data.size(); ++i) {
    double d1 = 0, d2 = 0;
    EpipolarDistances(f_px, data.pixels1[i], data.pixels2[i], &d1, &d2);
    for (double d : {d1, d2}) {
      const double chi2 = d * d / sigma_sq;
      if (chi2 <= kChi2OneDof) score += kChi2OneDof - chi2;
    }
  }
  return score;
}

double HomographyScore(const TwoViewOptions& options, const CameraIntrinsics& camera, const Eigen::Matrix3d& h_centred,
                       const Correspondences& data) {
  const double sigma_sq = options.ransac_threshold_px * options.ransac_threshold_px / kChi2OneDof;
  const Eigen::Matrix3d h_px = HomographyToPixels(camera, h_centred);
  const Eigen::Matrix3d h_px_inv = h_px.inverse();
  double score = 0;
  for (int i = 0; i < data.size(); ++i) {
    double e12 = 0, e21 = 0;
    TransferErrors(h_px, h_px_inv, data.pixels1[i], data.pixels2[i], &e12, &e21);
    for (double e : {e12, e21}) {
      const double chi2 = e / sigma_sq;
      if (chi2 <= kChi2TwoDof) score += kChi2TwoDof - chi2;
    }
  }
  return score;
}

}  // namespace selfcal::twoview::internal
