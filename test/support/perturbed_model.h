// A calibrated-looking model for the tests of the exports and of compensation: every parameter of rho moved
// uniformly by up to `length_m` / `angle_rad` (seeded), the betas left at nominal unless `with_beta`.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include "kinematics/robot_model.h"

namespace selfcal::testing {

inline RobotModel PerturbedModel(const RobotModel& nominal, double length_m, double angle_rad, bool with_beta,
                                 std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const KinematicParameters names(nominal.num_joints());
  Eigen::VectorXd rho = KinematicParameters::Nominal(nominal);
  for (int i = 0; i < rho.size(); ++i) {
    if (!with_beta && names.name(i).find(".beta") != std::string::npos) continue;
    rho[i] += (names.kind(i) == ParameterKind::kLength ? length_m : angle_rad) * u(rng);
  }
  return ApplyParameters(nominal, rho);
}

}  // namespace selfcal::testing
