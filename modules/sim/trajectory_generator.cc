#include "sim/trajectory_generator.h"

#include <cmath>
#include <algorithm>
#include <sstream>

namespace selfcal::sim {

namespace {

// Camera pose at centre c looking at `aim`, optical axis z, x axis as close as possible to x_reference,
// then rolled about z.
Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& aim, const Eigen::Vector3d& x_reference,
              double roll_rad) {
  const Eigen::Vector3d z = (aim - centre).normalized();
  const Eigen::Vector3d x = (x_reference - x_reference.dot(z) * z).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return Rigid3(r * RotZ(roll_rad), centre);
}

// Joint-space distance, wrapped joint by joint: used to pick the IK branch closest to the previous pose.
double JointDistance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

GeneratedTrajectory MakeArcTrajectory(const RobotModel& nominal, const ArcTrajectoryOptions& o) {
  GeneratedTrajectory out;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(nominal);
  const int n = nominal.num_joints();
  if (static_cast<int>(o.home_joints_deg.size()) != n) {
    out.message = "home_joints_deg has " + std::to_string(o.home_joints_deg.size()) + " values, the robot has " +
                  std::to_string(n) + " joints";
    return out;
  }
  Eigen::VectorXd home(n);
  for (int j = 0; j < n; ++j) home[j] = DegToRad(o.home_joints_deg[j]);
  const Rigid3 home_cam = BaseFromCam(nominal, rho, home);
  const Eigen::Vector3d view0 = home_cam.rotation.col(2);
  const Eigen::Vector3d target = home_cam.translation + o.distance_m * view0;
  const double elevation0 = std::asin(std::clamp(-view0.z(), -1.0, 1.0));
  const double azimuth0 = std::atan2(view0.y(), view0.x());
  std::vector<Rigid3> targets;
  for (int k = 0; k < o.num_poses; ++k) {
    const double s = o.num_poses > 1 ? static_cast<double>(k) / (o.num_poses - 1) : 0.0;
    const double azimuth =
        azimuth0 + DegToRad(o.azimuth_start_deg + (o.azimuth_end_deg - o.azimuth_start_deg) * s);
    const double elevation = elevation0 + DegToRad(o.elevation_swing_deg) * std::sin(2 * kPi * s);
    const double distance = o.distance_m + o.distance_swing_m * std::sin(3 * kPi * s);
    const Eigen::Vector3d view(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                               -std::sin(elevation));
    const Eigen::Vector3d centre = target - distance * view;
    const Eigen::Vector3d aim =
        target + o.aim_wander_m * Eigen::Vector3d(std::cos(4 * kPi * s), std::sin(4 * kPi * s), 0.0);
    targets.push_back(LookAt(centre, aim, home_cam.rotation.col(0), DegToRad(o.roll_swing_deg) * std::sin(2 * kPi * s + 0.5)));
  }

  // First pose from home; then each pose continued from the previous one.
  Eigen::VectorXd previous;
  if (!SolveCameraIk(nominal, rho, targets[0], home, &previous) || !WithinLimits(nominal, previous, o.joint_margin_rad)) {
    out.message = "no inverse-kinematics solution within the joint limits for the first pose";
    return out;
  }
  out.joints.push_back(previous);
  for (int k = 1; k < o.num_poses; ++k) {
    Eigen::VectorXd q;
    if (!SolveCameraIk(nominal, rho, targets[k], previous, &q) || JointDistance(q, previous) > 1.0 ||
        !WithinLimits(nominal, q, o.joint_margin_rad)) {
      std::ostringstream msg;
      msg << "pose " << k << ": inverse kinematics left the joint limits or jumped branches";
      out.message = msg.str();
      return out;
    }
    out.joints.push_back(q);
    previous = q;
  }
  out.ok = true;
  return out;
}

}  // namespace selfcal::sim
