#include "kinematics/robot_model.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "base/status.h"
#include "kinematics/autodiff_jacobian.h"
#include "kinematics/damped_least_squares.h"

namespace selfcal {

const char* CameraMountName(CameraMount mount) {
  return mount == CameraMount::kEyeToHand ? "eye_to_hand" : "eye_in_hand";
}

bool ParseCameraMount(const std::string& text, CameraMount* mount) {
  if (text == "eye_in_hand") {
    *mount = CameraMount::kEyeInHand;
  } else if (text == "eye_to_hand") {
    *mount = CameraMount::kEyeToHand;
  } else {
    return false;
  }
  return true;
}

RobotModel RobotModel::FromDh(const std::string& name, DhConvention convention, const std::vector<DhRow>& rows,
                              const std::vector<JointLimits>& limits, const Rigid3& base_from_link0,
                              const Rigid3& flange_from_cam) {
  RobotModel model;
  model.name = name;
  model.limits = limits;
  model.base_from_link0 = base_from_link0;
  model.flange_from_cam = flange_from_cam;
  const int n = static_cast<int>(rows.size());
  model.links.resize(n);
  if (convention == DhConvention::kModified) {
    for (int i = 0; i < n; ++i) {
      model.links[i] = LinkParameters{rows[i].alpha, rows[i].a, 0.0, rows[i].theta, rows[i].d};
    }
    return model;
  }
  // Standard: prod_i Rz(q_i+theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i). Tx and Rx about the same axis commute,
  // so the chain regroups exactly as [Rz Tz]_1 [Rx(alpha_1) Tx(a_1) Rz Tz]_2 ... [Tx(a_n) Rx(alpha_n)].
  for (int i = 0; i < n; ++i) {
    const double alpha = i == 0 ? 0.0 : rows[i - 1].alpha;
    const double a = i == 0 ? 0.0 : rows[i - 1].a;
    model.links[i] = LinkParameters{alpha, a, 0.0, rows[i].theta, rows[i].d};
  }
  if (n > 0) {
    model.link_n_from_flange = Rigid3(RotX(rows[n - 1].alpha), Eigen::Vector3d(rows[n - 1].a, 0, 0));
  }
  return model;
}

std::string RobotModel::Validate() const {
  std::ostringstream out;
  if (links.empty()) out << "the robot has no joints\n";
  if (limits.size() != links.size()) {
    out << "joint limits for " << limits.size() << " joints, but the DH table has " << links.size() << " rows\n";
  }
  for (size_t i = 0; i < links.size(); ++i) {
    const LinkParameters& l = links[i];
    for (double v : {l.alpha, l.a, l.beta, l.theta, l.d}) {
      if (!std::isfinite(v)) out << "joint " << i + 1 << ": non-finite DH value\n";
    }
    if (std::abs(l.a) > 10 || std::abs(l.d) > 10) out << "joint " << i + 1 << ": |a| or |d| above 10 m\n";
  }
  for (size_t i = 0; i < limits.size(); ++i) {
    if (!std::isfinite(limits[i].min_rad) || !std::isfinite(limits[i].max_rad) ||
        limits[i].min_rad >= limits[i].max_rad) {
      out << "joint " << i + 1 << ": limits [" << RadToDeg(limits[i].min_rad) << ", " << RadToDeg(limits[i].max_rad)
          << "] deg are not an interval\n";
    }
  }
  return out.str();
}

KinematicParameters::KinematicParameters(int num_joints) : num_joints_(num_joints) {
  const char* pose_names[6] = {"tx", "ty", "tz", "rx", "ry", "rz"};
  for (int k = 0; k < 6; ++k) {
    names_.push_back(std::string("base.") + pose_names[k]);
    kinds_.push_back(k < 3 ? ParameterKind::kLength : ParameterKind::kAngle);
  }
  const char* link_names[5] = {"alpha", "a", "beta", "theta", "d"};
  const ParameterKind link_kinds[5] = {ParameterKind::kAngle, ParameterKind::kLength, ParameterKind::kAngle,
                                       ParameterKind::kAngle, ParameterKind::kLength};
  for (int i = 0; i < num_joints; ++i) {
    for (int k = 0; k < 5; ++k) {
      names_.push_back("j" + std::to_string(i + 1) + "." + link_names[k]);
      kinds_.push_back(link_kinds[k]);
    }
  }
  for (int k = 0; k < 6; ++k) {
    names_.push_back(std::string("cam.") + pose_names[k]);
    kinds_.push_back(k < 3 ? ParameterKind::kLength : ParameterKind::kAngle);
  }
}

int KinematicParameters::IndexOf(const std::string& name) const {
  for (int i = 0; i < size(); ++i) {
    if (names_[i] == name) return i;
  }
  return -1;
}

Eigen::VectorXd KinematicParameters::Nominal(const RobotModel& model) {
  Eigen::VectorXd rho = Eigen::VectorXd::Zero(model.num_parameters());
  for (int i = 0; i < model.num_joints(); ++i) {
    const LinkParameters& l = model.links[i];
    rho.segment<5>(JointOffset(i)) << l.alpha, l.a, l.beta, l.theta, l.d;
  }
  return rho;
}

RobotModel ApplyParameters(const RobotModel& model, const Eigen::VectorXd& rho) {
  SELFCAL_CHECK(rho.size() == model.num_parameters(), "rho has " << rho.size() << " entries, the model needs " << model.num_parameters());
  RobotModel out = model;
  const int n = model.num_joints();
  out.base_from_link0 = model.base_from_link0 * RigidFromTranslationRotvec(rho.data());
  for (int i = 0; i < n; ++i) {
    const double* p = rho.data() + KinematicParameters::JointOffset(i);
    out.links[i] = LinkParameters{p[0], p[1], p[2], p[3], p[4]};
  }
  const Rigid3 cam_correction = RigidFromTranslationRotvec(rho.data() + 6 + 5 * n);
  if (model.mount == CameraMount::kEyeToHand) {
    out.base_from_cam = model.base_from_cam * cam_correction;
  } else {
    out.flange_from_cam = model.flange_from_cam * cam_correction;
  }
  return out;
}

Rigid3 BaseFromFlange(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q) {
  return BaseFromFlange<double>(model, rho.data(), q.data());
}

Rigid3 BaseFromCam(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q) {
  return BaseFromCam<double>(model, rho.data(), q.data());
}

Rigid3 PointsFromCam(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q) {
  return PointsFromCam<double>(model, rho.data(), q.data());
}

std::vector<int> ParallelAxisPairs(const RobotModel& model, double tol) {
  std::vector<int> pairs;
  for (int i = 1; i < model.num_joints(); ++i) {
    const LinkParameters& l = model.links[i];
    if (std::abs(std::sin(l.alpha)) < tol && std::abs(std::sin(l.beta)) < tol) pairs.push_back(i);
  }
  return pairs;
}

void ScaleLengths(double s, RobotModel* model, Eigen::VectorXd* rho) {
  SELFCAL_CHECK(std::isfinite(s) && s > 0, "scale " << s << " must be finite and positive");
  const KinematicParameters params(model->num_joints());
  for (int i = 0; i < params.size(); ++i) {
    if (params.kind(i) == ParameterKind::kLength) (*rho)[i] *= s;
  }
  for (LinkParameters& l : model->links) {
    l.a *= s;
    l.d *= s;
  }
  model->base_from_link0.translation *= s;
  model->link_n_from_flange.translation *= s;
  model->flange_from_cam.translation *= s;
  model->base_from_cam.translation *= s;
}

bool WithinLimits(const RobotModel& model, const Eigen::VectorXd& q, double margin_rad) {
  if (q.size() != model.num_joints()) return false;
  for (int i = 0; i < q.size(); ++i) {
    if (!(q[i] >= model.limits[i].min_rad + margin_rad && q[i] <= model.limits[i].max_rad - margin_rad)) return false;
  }
  return true;
}

bool SolveCameraIk(const RobotModel& model, const Eigen::VectorXd& rho, const Rigid3& base_from_cam_target,
                   const Eigen::VectorXd& seed, Eigen::VectorXd* q) {
  Eigen::VectorXd x = seed;
  // Residual: target^-1 * current as (translation, rotation vector); zero at the solution.
  const Rigid3 cam_target_from_base = base_from_cam_target.Inverse();
  auto residual = [&](const auto* qq, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(qq)>>;
    std::vector<T> rho_t(rho.size());
    for (int i = 0; i < rho.size(); ++i) rho_t[i] = T(rho[i]);
    const Rigid3T<T> err = cam_target_from_base.Cast<T>() * BaseFromCam<T>(model, rho_t.data(), qq);
    out[0] = err.translation.x();
    out[1] = err.translation.y();
    out[2] = err.translation.z();
    // Small-angle rotation error from the antisymmetric part; exact zero at the solution.
    out[3] = T(0.5) * (err.rotation(2, 1) - err.rotation(1, 2));
    out[4] = T(0.5) * (err.rotation(0, 2) - err.rotation(2, 0));
    out[5] = T(0.5) * (err.rotation(1, 0) - err.rotation(0, 1));
  };
  // The antisymmetric part also vanishes at a 180 degree error: the full rotation is checked at the end.
  MinimiseDampedLeastSquares(
      [&](const Eigen::VectorXd& at, Eigen::VectorXd* r, Eigen::MatrixXd* jac) { *jac = AutodiffJacobian(residual, at, 6, r); },
      &x);
  const Rigid3 reached = BaseFromCam(model, rho, x);
  const PoseDifference diff = ComparePoses(reached, base_from_cam_target);
  *q = x;
  return diff.position_m < 1e-10 && diff.rotation_rad < 1e-10;
}

}  // namespace selfcal
