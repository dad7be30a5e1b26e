// A RobotModel (typically the calibrated one) as a DH table in a given convention, when it can be written
// there exactly (docs/calibrated-model-format.md, "The calibrated robot in your convention").
//
// The model is modified DH with Hayati's beta (robot_model.h):
//   base_from_link0 * prod_i Rx(alpha_i) Tx(a_i) Ry(beta_i) Rz(q_i + theta_i) Tz(d_i) * link_n_from_flange
// - modified (Craig): rows Rx(alpha) Tx(a) Rz(q + theta) Tz(d); exact when every beta is zero.
// - standard (distal): rows Rz(q + theta) Tz(d) Tx(a) Rx(alpha), regrouped the other way round from
//   RobotModel::FromDh: row i takes joint i's theta and d and joint i+1's alpha and a, joint 1's alpha and a
//   go into base_from_link0, and the last row's a and alpha are link_n_from_flange, which must then be
//   Tx(a) Rx(alpha) (a standard table has no other flange transform). Exact when every beta is zero and
//   link_n_from_flange has that form.
// - modified_hayati: always exact.
// A model that is not expressible gets every reason in words and what dropping the offending terms would
// cost: the largest flange position and rotation change over seeded random joints within the limits.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kinematics/robot_model.h"

namespace selfcal {

// |beta| at or below this (rad) counts as zero: dropping it moves a 1 m arm by at most 1e-12 m.
inline constexpr double kNegligibleBetaRad = 1e-12;

struct DhTable {
  DhConvention convention = DhConvention::kModified;
  bool hayati = false;  // modified rows with beta (modified_hayati)
  std::vector<DhRow> rows;
  std::vector<double> betas;  // hayati only
  std::vector<JointLimits> limits;
  Rigid3 base_from_link0;
  Rigid3 link_n_from_flange;  // identity and unused for standard
  Rigid3 flange_from_cam;
};

struct DhExpression {
  bool exact = false;
  DhTable table;                   // meaningful only when exact
  std::vector<std::string> losses;  // why not, one sentence each (empty when exact)
  // What dropping the terms the convention cannot hold would change (flange, over the random joints).
  double dropped_position_m = 0;
  double dropped_rotation_rad = 0;
};

// `convention_name`: "standard", "modified" or "modified_hayati".
DhExpression ExpressAsDh(const RobotModel& model, const std::string& convention_name, int samples = 200,
                         std::uint64_t seed = 1);

// The table as a RobotModel again (RobotModel::FromDh plus beta and link_n_from_flange).
RobotModel ModelOfDhTable(const std::string& name, const DhTable& table);

}  // namespace selfcal
