#include "calibration/yardstick_scale.h"

#include <cmath>

namespace selfcal::calibration {

YardstickScale YardstickScaleOf(const RobotModel& robot, const bundle::BundleReport& bundle, int yardsticks) {
  YardstickScale out;
  out.yardsticks = yardsticks;
  if (yardsticks == 0) {
    out.reason = "the set has no yardstick";
    return out;
  }
  const KinematicParameters params(robot.num_joints());
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(robot);
  if (bundle.rho.size() != nominal.size()) {
    out.reason = "no kinematic parameters were estimated";
    return out;
  }
  // g: d s / d rho over the free columns of the covariance (free_indices order).
  const int free = static_cast<int>(bundle.free_indices.size());
  Eigen::VectorXd g = Eigen::VectorXd::Zero(free);
  double sum_nc = 0, sum_nn = 0;
  for (int k = 0; k < free; ++k) {
    const int i = bundle.free_indices[k];
    if (params.kind(i) != ParameterKind::kLength || !(std::abs(nominal[i]) >= kMinScaleLengthM)) continue;
    out.lengths.push_back(params.name(i));
    sum_nc += (bundle.rho[i] - nominal[i]) * nominal[i];
    sum_nn += nominal[i] * nominal[i];
    g[k] = nominal[i];
  }
  if (out.lengths.empty()) {
    out.reason = "no link length of the description was free (of at least 10 mm)";
    return out;
  }
  out.available = true;
  out.scale = 1 + sum_nc / sum_nn;
  g /= sum_nn;
  const Eigen::MatrixXd& c = bundle.covariance_free;
  out.stddev = bundle.covariance_available && c.rows() >= free ? std::sqrt(g.dot(c.topLeftCorner(free, free) * g)) : NAN;
  return out;
}

}  // namespace selfcal::calibration
