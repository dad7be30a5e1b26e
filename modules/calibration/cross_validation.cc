#include "calibration/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "calibration/heldout_chi_square.h"

namespace selfcal::calibration {

namespace {

// Identification pose indices in a seeded order (Fisher-Yates on mt19937_64: the same on every platform).
std::vector<int> ShuffledPoses(const ObservationSet& obs, std::uint64_t seed) {
  std::vector<int> poses = obs.PosesWithRole(PoseRole::kIdentification);
  std::mt19937_64 rng(seed);
  for (size_t k = poses.size(); k > 1; --k) std::swap(poses[k - 1], poses[rng() % k]);
  return poses;
}

// One fold: `run` on the set without `held_out` (made verification poses), and its figure of them.
CrossValidationFold RunFold(const ObservationSet& obs, const std::vector<int>& held_out, const FoldRunner& run) {
  CrossValidationFold fold;
  ObservationSet train = obs;
  for (int p : held_out) {
    train.poses[p].role = PoseRole::kVerification;
    fold.held_out.push_back(obs.poses[p].id);
  }
  const FoldFit fit = run(train);
  fold.outcome = fit.outcome;
  if (fit.outcome != bundle::Outcome::kConverged) {
    fold.message = fit.message;
    return fold;
  }
  if (!fit.heldout.ok) {
    fold.message = fit.heldout.message;
    return fold;
  }
  fold.figure = fit.heldout.overall;
  return fold;
}

// The bundle on a fold's training set, started from the whole solve, predicting the fold at the stated noise.
FoldFit FitBundle(const ObservationSet& train, const BundleStageReport& full, const BundleStageOptions& options) {
  FoldFit fit;
  const bundle::BundleReport b = bundle::RunBundleAdjustment(train, full.bundle.rho, full.bundle.fx_px, options.bundle);
  fit.outcome = b.outcome;
  fit.message = b.message;
  if (b.outcome != bundle::Outcome::kConverged) return fit;
  double noise = 0;
  int noise_dof = 0;
  fit.heldout = HeldOutReprojectionOfBundle(train, b, &noise, &noise_dof, train.pixel_noise_px);
  return fit;
}

}  // namespace

CrossValidationReport CrossValidateWith(const ObservationSet& obs, int folds, std::uint64_t seed, const FoldRunner& run) {
  CrossValidationReport report;
  report.folds = folds;
  report.seed = seed;
  const std::vector<int> poses = ShuffledPoses(obs, seed);
  if (!obs.PosesWithRole(PoseRole::kVerification).empty()) {
    report.message = "not run: the verification poses give the held-out figure";
    return report;
  }
  if (folds < 2) {
    report.message = "not run (folds = " + std::to_string(folds) + ")";
    return report;
  }
  if (static_cast<int>(poses.size()) < 2 * folds) {
    report.message = "not run: " + std::to_string(poses.size()) + " identification poses are too few for " +
                     std::to_string(folds) + " folds (two poses a fold at least)";
    return report;
  }
  report.ran = true;
  double sum2 = 0, scatter = 0;  // scatter: sum over folds of share^2 / pose_noise_dof
  HeldOutFigure& pooled = report.pooled;
  pooled.chi_square = 0;
  pooled.max_px = 0;
  for (int f = 0; f < folds; ++f) {
    std::vector<int> held_out;
    for (size_t k = f; k < poses.size(); k += folds) held_out.push_back(poses[k]);
    std::sort(held_out.begin(), held_out.end());
    report.per_fold.push_back(RunFold(obs, held_out, run));
    const HeldOutFigure& figure = report.per_fold.back().figure;
    if (figure.num_residuals > 0) {
      sum2 += figure.rms_px * figure.rms_px * figure.num_residuals;
      report.folds_passed += figure.test_passed ? 1 : 0;
      ++report.folds_tested;
      pooled.num_residuals += figure.num_residuals;
      pooled.dof += figure.dof;
      pooled.chi_square += figure.chi_square;
      pooled.pose_share += figure.pose_share;
      if (figure.pose_noise_dof > 0) scatter += figure.pose_share * figure.pose_share / figure.pose_noise_dof;
      pooled.max_px = std::max(pooled.max_px, figure.max_px);
    }
  }
  if (pooled.num_residuals > 0) {
    pooled.rms_px = std::sqrt(sum2 / pooled.num_residuals);
    // Each fold's pose part scaled by its own estimate's scatter, taken as independent between folds (they
    // share most of their data: a pooled estimate is no better than that, so this errs towards refusing).
    pooled.pose_noise_dof = DegreesOfFreedomOf(2 * scatter / (pooled.pose_share * pooled.pose_share));
    pooled.chi_square_limit =
        ChiSquareQuantile(kHeldOutTestLevel, pooled.dof, 0, pooled.pose_share, pooled.pose_noise_dof);
    pooled.p_value = ChiSquareUpperTail(pooled.chi_square, pooled.dof, 0, pooled.pose_share, pooled.pose_noise_dof);
    pooled.test_passed = pooled.chi_square <= pooled.chi_square_limit;
  } else {
    pooled = HeldOutFigure();
  }
  report.message = "held-out RMS over " + std::to_string(folds) + " folds";
  return report;
}

CrossValidationReport CrossValidate(const ObservationSet& obs, const BundleStageReport& full,
                                    const BundleStageOptions& options, int folds, std::uint64_t seed) {
  CrossValidationReport report = CrossValidateWith(
      obs, folds, seed, [&](const ObservationSet& train) { return FitBundle(train, full, options); });
  if (!report.ran) return report;
  const double depth = MedianCameraToDotDistance(obs, full.fit_geometry, full.bundle.dots_in_base);
  if (std::isfinite(depth) && full.bundle.fx_px > 0) {
    report.mm_per_px = depth * 1e3 / full.bundle.fx_px;
    report.rms_mm = report.pooled.rms_px * report.mm_per_px;
  }
  return report;
}

}  // namespace selfcal::calibration
