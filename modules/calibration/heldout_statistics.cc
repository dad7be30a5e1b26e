// The held-out test's quantiles and tails (heldout_reprojection.h): chi-square, or dof x F(dof, noise_dof)
// when the noise was estimated.
#include <cmath>

#include "calibration/heldout_reprojection.h"

namespace selfcal::calibration {

namespace {

// P(F > f) for F ~ F(d1, d2) (d2 = 0: infinite, i.e. chi-square(d1) / d1), Paulson's approximation:
// z = ((1 - b) f^(1/3) - (1 - a)) / sqrt(b f^(2/3) + a), a = 2 / (9 d1), b = 2 / (9 d2), standard normal.
double FUpperTail(double f, int d1, int d2) {
  const double a = 2.0 / (9.0 * d1), b = d2 > 0 ? 2.0 / (9.0 * d2) : 0.0;
  const double c = std::cbrt(f);
  const double z = ((1 - b) * c - (1 - a)) / std::sqrt(b * c * c + a);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

}  // namespace

double ChiSquareQuantile(double p, int dof, int noise_dof) {
  if (dof <= 0 || noise_dof < 0 || !(p > 0 && p < 1)) return NAN;
  // Bisection on the decreasing upper tail, in f = x / dof.
  double lo = 0, hi = 1;
  while (FUpperTail(hi, dof, noise_dof) > 1 - p && hi < 1e12) hi *= 2;
  for (int iteration = 0; iteration < 200 && hi - lo > 1e-13 * hi; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (FUpperTail(mid, dof, noise_dof) > 1 - p ? lo : hi) = mid;
  }
  return dof * 0.5 * (lo + hi);
}

double ChiSquareUpperTail(double x, int dof, int noise_dof) {
  if (dof <= 0 || noise_dof < 0 || !std::isfinite(x)) return NAN;
  if (x <= 0) return 1.0;
  return FUpperTail(x / dof, dof, noise_dof);
}

}  // namespace selfcal::calibration
