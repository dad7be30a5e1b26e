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

namespace {

// The flange target of the eye-to-hand path at s in [0, 1): the plate's centre wandering about plate0 (in the
// camera's axes), its normal tilted by tilt_scale * the path's tilt away from the direction to the camera,
// the flange rolled about it.
Rigid3 EyeToHandTarget(const EyeToHandTrajectoryOptions& o, const Rigid3& camera, const Rigid3& home_flange,
                       const Eigen::Vector3d& plate0, double s, double tilt_scale) {
  const Eigen::Vector3d wander(o.wander_m.x() * std::sin(2 * kPi * s), o.wander_m.y() * std::sin(4 * kPi * s + 0.5),
                               o.wander_m.z() * std::sin(6 * kPi * s + 1.0));
  const Eigen::Vector3d plate = plate0 + camera.rotation * wander;
  const Eigen::Vector3d to_camera = (camera.translation - plate).normalized();
  const double phase = 2 * kPi * 3 * s;  // the tilt's axis turns with s
  const Eigen::Vector3d across = camera.rotation * Eigen::Vector3d(std::cos(phase), std::sin(phase), 0);
  const Eigen::Vector3d axis = to_camera.cross(across).normalized();
  const double tilt = tilt_scale * DegToRad(o.tilt_deg) * (0.55 + 0.45 * std::sin(2 * kPi * 2 * s));
  const Eigen::Vector3d z = Eigen::AngleAxisd(tilt, axis) * to_camera;
  Eigen::Vector3d x = home_flange.rotation.col(0) - home_flange.rotation.col(0).dot(z) * z;
  x = Eigen::AngleAxisd(DegToRad(o.roll_swing_deg) * std::sin(2 * kPi * s + 0.3), z) * x.normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return Rigid3(r, plate - o.plate_standoff_m * z);
}

}  // namespace

GeneratedTrajectory MakeEyeToHandTrajectory(const RobotModel& nominal, const EyeToHandTrajectoryOptions& o) {
  GeneratedTrajectory out;
  const int n = nominal.num_joints();
  if (static_cast<int>(o.home_joints_deg.size()) != n) {
    out.message = "home_joints_deg has " + std::to_string(o.home_joints_deg.size()) + " values, the robot has " +
                  std::to_string(n) + " joints";
    return out;
  }
  // The flange's inverse kinematics: the same arm with the camera at the flange.
  RobotModel flange_model = nominal;
  flange_model.mount = CameraMount::kEyeInHand;
  flange_model.flange_from_cam = Rigid3();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(flange_model);
  Eigen::VectorXd home(n);
  for (int j = 0; j < n; ++j) home[j] = DegToRad(o.home_joints_deg[j]);
  const Rigid3 home_flange = BaseFromFlange(flange_model, rho, home);
  const Eigen::Vector3d plate0 = home_flange * Eigen::Vector3d(0, 0, o.plate_standoff_m);
  // Where the arm cannot follow the path (a joint limit, a wrist singularity that flips a branch), the pose
  // is taken a little further along it or less tilted.
  const double shifts[][2] = {{0, 1}, {0, 0.5}, {0.3, 1}, {0.3, 0.5}, {-0.3, 0.5}, {0, 0}};
  Eigen::VectorXd previous = home;
  for (int k = 0; k < o.num_poses; ++k) {
    std::string problem;
    Eigen::VectorXd q;
    for (const auto& [shift, tilt_scale] : shifts) {
      const double s = o.num_poses > 1 ? (k + shift) / o.num_poses : 0.0;
      const Rigid3 target = EyeToHandTarget(o, nominal.base_from_cam, home_flange, plate0, s, tilt_scale);
      const bool solved = SolveCameraIk(flange_model, rho, target, previous, &q);
      problem = !solved                                               ? "has no solution"
                : JointDistance(q, previous) > 1.2                    ? "jumped branches"
                : !WithinLimits(flange_model, q, o.joint_margin_rad) ? "left the joint limits"
                                                                      : "";
      if (problem.empty()) break;
    }
    if (!problem.empty()) {
      std::ostringstream joints;
      for (Eigen::Index j = 0; j < q.size(); ++j) joints << (j ? ", " : "") << std::lround(RadToDeg(q[j]));
      out.message = "eye-to-hand pose " + std::to_string(k) + ": the flange's inverse kinematics " + problem + " (" +
                    joints.str() + " deg)";
      return out;
    }
    out.joints.push_back(q);
    previous = q;
  }
  out.ok = true;
  return out;
}

}  // namespace selfcal::sim
