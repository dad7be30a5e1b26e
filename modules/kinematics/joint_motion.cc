#include "kinematics/joint_motion.h"

#include <algorithm>
#include <cstdio>

#include "geometry/rigid3.h"

namespace selfcal {

std::vector<BarelyMovingJoint> BarelyMovingJoints(const std::vector<Eigen::VectorXd>& joints, double threshold_rad) {
  std::vector<BarelyMovingJoint> out;
  if (joints.empty()) return out;
  for (Eigen::Index j = 0; j < joints.front().size(); ++j) {
    double lo = joints.front()[j], hi = lo;
    for (const Eigen::VectorXd& q : joints) {
      if (j >= q.size()) return out;
      lo = std::min(lo, q[j]);
      hi = std::max(hi, q[j]);
    }
    if (hi - lo < threshold_rad) out.push_back({static_cast<int>(j) + 1, hi - lo});
  }
  return out;
}

std::string BarelyMovesSentence(const BarelyMovingJoint& joint, const std::string& poses) {
  char degrees[32];
  std::snprintf(degrees, sizeof(degrees), "%.1f", RadToDeg(joint.range_rad));
  return "joint " + std::to_string(joint.joint) + " barely moves (" + degrees + " deg over " + poses +
         "): the parameters beside it are hard to tell apart";
}

}  // namespace selfcal
