#include "robot/robot.h"

#include <cmath>
#include <cstring>
#include <algorithm>
#include <sstream>

namespace selfcal::robot {
namespace {

std::string Numbers(const Eigen::VectorXd& v) {
  std::ostringstream out;
  out.precision(6);
  for (Eigen::Index i = 0; i < v.size(); ++i) out << (i ? " " : "") << v[i];
  return out.str();
}

}  // namespace

const char* RobotErrorName(RobotError error) {
  switch (error) {
    case RobotError::kNone:
      return "none";
    case RobotError::kNotConnected:
      return "not_connected";
    case RobotError::kRejected:
      return "rejected";
    case RobotError::kTimeout:
      return "timeout";
    case RobotError::kProtectiveStop:
      return "protective_stop";
    case RobotError::kEmergencyStop:
      return "emergency_stop";
    case RobotError::kDisconnected:
      return "disconnected";
    case RobotError::kBadReading:
      return "bad_reading";
    case RobotError::kProtocol:
      return "protocol";
    case RobotError::kOperatorAbort:
      return "operator_abort";
  }
  return "unknown";
}

Status RobotFailure(RobotError error, const std::string& message) {
  if (error == RobotError::kNone) throw InvalidArgument("RobotFailure needs an error, not kNone: " + message);
  return Status::Error(ErrorCode::kHardware, message).WithDetail(kRobotErrorDomain, static_cast<int>(error));
}

RobotError RobotErrorOf(const Status& status) {
  if (status.ok() || std::strcmp(status.detail_domain(), kRobotErrorDomain) != 0) return RobotError::kNone;
  return static_cast<RobotError>(status.detail());
}

const char* MotionStateName(MotionState state) {
  switch (state) {
    case MotionState::kIdle:
      return "idle";
    case MotionState::kMoving:
      return "moving";
    case MotionState::kProtectiveStop:
      return "protective_stop";
    case MotionState::kEmergencyStop:
      return "emergency_stop";
    case MotionState::kFault:
      return "fault";
  }
  return "unknown";
}

double QuinticMoveDuration(const Eigen::VectorXd& from_rad, const Eigen::VectorXd& to_rad,
                           const Eigen::VectorXd& max_velocity_rad_s, double velocity_scaling, int* limiting_joint) {
  double duration_s = 0;
  int limiting = -1;
  for (Eigen::Index j = 0; j < from_rad.size(); ++j) {
    const double t = kQuinticPeakRate * std::abs(to_rad[j] - from_rad[j]) / (max_velocity_rad_s[j] * velocity_scaling);
    if (t > duration_s) {
      duration_s = t;
      limiting = static_cast<int>(j);
    }
  }
  if (limiting_joint != nullptr) *limiting_joint = limiting;
  return duration_s;
}

std::string CheckJointLimits(const JointLimits& limits) {
  const Eigen::Index n = limits.lower_rad.size();
  std::ostringstream problem;
  problem.precision(10);
  if (n == 0 || limits.upper_rad.size() != n || limits.max_velocity_rad_s.size() != n) {
    problem << "joint limits need one lower, upper and max velocity per joint, got " << limits.lower_rad.size()
            << ", " << limits.upper_rad.size() << " and " << limits.max_velocity_rad_s.size();
    return problem.str();
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const double lower = limits.lower_rad[j], upper = limits.upper_rad[j], vmax = limits.max_velocity_rad_s[j];
    if (!std::isfinite(lower) || !std::isfinite(upper) || !(lower < upper)) {
      problem << "joint " << j + 1 << ": limits [" << lower << ", " << upper << "] rad are not a finite interval";
      return problem.str();
    }
    if (!std::isfinite(vmax) || !(vmax > 0)) {
      problem << "joint " << j + 1 << ": max velocity " << vmax << " rad/s is not positive and finite";
      return problem.str();
    }
  }
  return "";
}

std::string IdentityRefusal(const RobotIdentity& now, const std::optional<RobotIdentity>& first,
                            const std::optional<RobotIdentity>& expected, const std::string& name) {
  const auto differs = [](const RobotIdentity& a, const RobotIdentity& b, bool skip_empty) {
    const auto field = [&](const std::string& x, const std::string& y) { return !(skip_empty && x.empty()) && x != y; };
    return field(a.model, b.model) || field(a.serial, b.serial) || field(a.calibration_id, b.calibration_id);
  };
  const auto said = [](const RobotIdentity& i) { return i.model + " serial " + i.serial + " " + i.calibration_id; };
  if (first && differs(*first, now, false)) {
    return name + ": the controller is not the one first connected (" + said(*first) + ", now " + said(now) +
           "); refusing it";
  }
  if (expected && differs(*expected, now, true)) {
    return name + ": the controller is not the expected robot (" + said(now) + "); refusing it";
  }
  return "";
}

std::string CheckMoveTarget(const JointLimits& limits, const Eigen::VectorXd& target_rad, double velocity_scaling) {
  std::ostringstream problem;
  problem.precision(10);
  if (!(velocity_scaling > 0 && velocity_scaling <= 1)) {
    problem << "velocity scaling " << velocity_scaling << " is not in (0, 1]";
    return problem.str();
  }
  if (target_rad.size() != limits.lower_rad.size()) {
    problem << "target has " << target_rad.size() << " joints, the robot has " << limits.lower_rad.size();
    return problem.str();
  }
  for (Eigen::Index j = 0; j < target_rad.size(); ++j) {
    const double q = target_rad[j];
    if (!std::isfinite(q)) {
      problem << "joint " << j + 1 << ": target " << q << " rad is not finite";
      return problem.str();
    }
    if (q < limits.lower_rad[j] || q > limits.upper_rad[j]) {
      problem << "joint " << j + 1 << ": target " << q << " rad is outside its limits [" << limits.lower_rad[j]
              << ", " << limits.upper_rad[j] << "] rad";
      return problem.str();
    }
  }
  return "";
}

Status CheckStartAtRest(const std::function<Result<JointReading>()>& read, const std::function<void(double)>& sleep,
                        const JointLimits& limits, const RestCheck& rest, const std::string& name) {
  JointReading readings[2];
  for (int k = 0; k < 2; ++k) {
    if (k == 1) sleep(rest.interval_s);
    Result<JointReading> r = read();
    if (!r.ok()) return r.status();
    const JointReading& q = *r;
    const std::string which = name + ": the start reading " + (k == 0 ? "" : "(again) ");
    if (q.position_rad.size() != limits.lower_rad.size() || q.velocity_rad_s.size() != q.position_rad.size()) {
      return RobotFailure(RobotError::kBadReading, which + "has " + std::to_string(q.position_rad.size()) +
                                                       " joints, the robot config has " +
                                                       std::to_string(limits.lower_rad.size()));
    }
    if (!q.position_rad.allFinite() || !q.velocity_rad_s.allFinite()) {
      return RobotFailure(RobotError::kBadReading, which + "is not finite: " + Numbers(q.position_rad) + " rad, " +
                                                       Numbers(q.velocity_rad_s) + " rad/s");
    }
    for (Eigen::Index j = 0; j < q.position_rad.size(); ++j) {
      if (q.position_rad[j] < limits.lower_rad[j] - 1e-9 || q.position_rad[j] > limits.upper_rad[j] + 1e-9) {
        std::ostringstream what;
        what << which << "has joint " << j + 1 << " at " << q.position_rad[j] << " rad, outside its limits ["
             << limits.lower_rad[j] << ", " << limits.upper_rad[j] << "] rad";
        return RobotFailure(RobotError::kBadReading, what.str());
      }
    }
    readings[k] = q;
  }
  const double moved = (readings[1].position_rad - readings[0].position_rad).cwiseAbs().maxCoeff();
  const double speed = std::max(readings[0].velocity_rad_s.cwiseAbs().maxCoeff(),
                                readings[1].velocity_rad_s.cwiseAbs().maxCoeff());
  if (moved > rest.tolerance_rad || speed > rest.velocity_rad_s) {
    std::ostringstream what;
    what << name << ": the arm is not at rest at connect: two readings " << rest.interval_s
         << " s apart differ by up to " << moved << " rad, joint speeds up to " << speed << " rad/s (at rest: "
         << rest.tolerance_rad << " rad, " << rest.velocity_rad_s << " rad/s)";
    return RobotFailure(RobotError::kBadReading, what.str());
  }
  return Status::Ok();
}

}  // namespace selfcal::robot
