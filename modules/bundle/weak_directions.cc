// Weak directions of the kinematic bundle adjustment: near-unidentifiable joint parameters held at the
// robot description's value (BundleOptions::weak_length_tolerance_m, weak_angle_tolerance_rad).
#include <algorithm>

#include "bundle/bundle_problem.h"

namespace selfcal::bundle::internal {

bool FindWeakParameters(const BundleData& data, const BundleState& state, const Gauge& gauge,
                        const IntrinsicsMask& estimate, double length_tolerance_m, double angle_tolerance_rad,
                        std::vector<identification::WeakColumn>* weak) {
  weak->clear();
  const int num_joints = data.robot.num_joints();
  const KinematicParameters params(num_joints);
  GlobalColumns columns;
  columns.kinematic = gauge.free_kinematic;
  for (int k : EstimatedIntrinsics(estimate)) {
    if (gauge.intrinsics_identifiable[k]) columns.intrinsics.push_back(k);
  }
  Eigen::MatrixXd reduced;
  if (!ReducedJacobian(data, state, columns, &reduced)) return false;
  const int nk = static_cast<int>(columns.kinematic.size());
  // The gauge's order over these columns: the intrinsics, then camera, base, joint by joint, betas last.
  std::vector<int> order;
  for (int k = 0; k < static_cast<int>(columns.intrinsics.size()); ++k) order.push_back(nk + k);
  Eigen::VectorXd tolerance = Eigen::VectorXd::Zero(columns.size());
  for (int c : identification::PreferredParameterOrder(num_joints)) {
    auto it = std::find(columns.kinematic.begin(), columns.kinematic.end(), c);
    if (it == columns.kinematic.end()) continue;
    const int local = static_cast<int>(it - columns.kinematic.begin());
    order.push_back(local);
    const bool joint = c >= KinematicParameters::JointOffset(0) && c < params.CamOffset();
    if (joint) tolerance[local] = params.kind(c) == ParameterKind::kLength ? length_tolerance_m : angle_tolerance_rad;
  }
  *weak = identification::FindWeakColumns(reduced, order, tolerance, GlobalNames(columns, num_joints));
  // Back to rho indices.
  for (identification::WeakColumn& w : *weak) w.column = columns.kinematic[w.column];
  return true;
}

}  // namespace selfcal::bundle::internal
