#include "observations/joint_limits.h"

#include "base/short_number.h"

namespace selfcal {

std::vector<std::string> PosesOutsideJointLimits(const ObservationSet& set) {
  std::vector<std::string> out;
  const RobotModel& robot = set.robot;
  for (size_t i = 0; i < set.poses.size(); ++i) {
    const PoseObservation& pose = set.poses[i];
    std::string joints;
    for (int j = 0; j < pose.joints_rad.size() && j < static_cast<int>(robot.limits.size()); ++j) {
      const JointLimits& l = robot.limits[j];
      const double q = pose.joints_rad[j];
      if (q >= l.min_rad - kJointLimitReadingToleranceRad && q <= l.max_rad + kJointLimitReadingToleranceRad) continue;
      joints += (joints.empty() ? "" : ", ") + std::string("joint ") + std::to_string(j + 1) + " = " +
                ShortNumber(RadToDeg(q)) + " deg outside [" + ShortNumber(RadToDeg(l.min_rad)) + ", " + ShortNumber(RadToDeg(l.max_rad)) +
                "] deg";
    }
    if (!joints.empty()) {
      out.push_back("pose " + pose.id + " (index " + std::to_string(i) + "): " + joints +
                    " of robot `" + robot.name + "`");
    }
  }
  return out;
}

}  // namespace selfcal
