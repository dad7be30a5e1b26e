// The held-out test's quantiles and tails (heldout_reprojection.h): chi-square, or dof x F(dof, noise_dof)
// when the noise was estimated, averaged over the estimated pose error's size.
#include <algorithm>
#include <cmath>
#include <vector>

#include "calibration/heldout_reprojection.h"

namespace selfcal::calibration {

namespace {

// P(F > f) for F ~ F(d1, d2) (d2 = 0: infinite, i.e. chi-square(d1) / d1), Paulson's approximation:
// z = ((1 - b) f^(1/3) - (1 - a)) / sqrt(b f^(2/3) + a), a = 2 / (9 d1), b = 2 / (9 d2), standard normal.
double FUpperTail(double f, double d1, int d2) {
  const double a = 2.0 / (9.0 * d1), b = d2 > 0 ? 2.0 / (9.0 * d2) : 0.0;
  const double c = std::cbrt(f);
  const double z = ((1 - b) * c - (1 - a)) / std::sqrt(b * c * c + a);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// lambda = nu / chi-square(nu) over a grid of u = log chi-square(nu), whose density is proportional to
// exp(nu u / 2 - e^u / 2), with the grid's normalised weights.
struct ScaleDraws {
  std::vector<double> scale, weight;
};
ScaleDraws DrawsOfTheEstimate(int nu) {
  constexpr int kPoints = 600;
  const double lo = std::log(1e-7 * nu), hi = std::log(nu + 40 * std::sqrt(2.0 * nu) + 40);
  const auto log_density = [nu](double u) { return 0.5 * nu * u - 0.5 * std::exp(u); };
  const double top = log_density(std::log(static_cast<double>(nu)));  // the mode
  ScaleDraws d;
  double total = 0;
  for (int i = 0; i < kPoints; ++i) {
    const double u = lo + (hi - lo) * (i + 0.5) / kPoints;
    d.scale.push_back(nu * std::exp(-u));
    d.weight.push_back(std::exp(log_density(u) - top));
    total += d.weight.back();
  }
  for (double& w : d.weight) w /= total;
  return d;
}

// The statistic's distribution (ChiSquareQuantile's comment), with the pose part's scale draws made once.
struct Statistic {
  int dof = 0, noise_dof = 0;
  double share = 0;   // the pose part, within [0, dof]; 0: none, or its size known
  ScaleDraws draws;   // of its size's estimate, when share > 0
};
Statistic StatisticOf(int dof, int noise_dof, double pose_share, int pose_noise_dof) {
  Statistic x{dof, noise_dof, std::clamp(pose_share, 0.0, static_cast<double>(dof)), {}};
  if (!(x.share > 0) || pose_noise_dof <= 0) x.share = 0;
  if (x.share > 0) x.draws = DrawsOfTheEstimate(pose_noise_dof);
  return x;
}

// P(X > x) in f = x / dof.
double UpperTail(double f, const Statistic& x) {
  if (x.share == 0) return FUpperTail(f, x.dof, x.noise_dof);
  const double rest = x.dof - x.share;
  double tail = 0;
  for (size_t i = 0; i < x.draws.scale.size(); ++i) {
    const double lambda = x.draws.scale[i];
    const double mean = rest + lambda * x.share, variance = 2 * (rest + lambda * lambda * x.share);
    const double k = 2 * mean * mean / variance;  // X ~ mean chi-square(k) / k
    tail += x.draws.weight[i] * FUpperTail(f * x.dof / mean, k, x.noise_dof);
  }
  return tail;
}

}  // namespace

double ChiSquareQuantile(double p, int dof, int noise_dof, double pose_share, int pose_noise_dof) {
  if (dof <= 0 || noise_dof < 0 || !(p > 0 && p < 1)) return NAN;
  const Statistic x = StatisticOf(dof, noise_dof, pose_share, pose_noise_dof);
  // Bisection on the decreasing upper tail, in f = x / dof.
  double lo = 0, hi = 1;
  while (UpperTail(hi, x) > 1 - p && hi < 1e12) hi *= 2;
  for (int iteration = 0; iteration < 200 && hi - lo > 1e-10 * hi; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (UpperTail(mid, x) > 1 - p ? lo : hi) = mid;
  }
  return dof * 0.5 * (lo + hi);
}

double ChiSquareUpperTail(double x, int dof, int noise_dof, double pose_share, int pose_noise_dof) {
  if (dof <= 0 || noise_dof < 0 || !std::isfinite(x)) return NAN;
  if (x <= 0) return 1.0;
  return UpperTail(x / dof, StatisticOf(dof, noise_dof, pose_share, pose_noise_dof));
}

}  // namespace selfcal::calibration
