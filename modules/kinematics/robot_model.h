// Module kinematics (ARCHITECTURE.md): RobotModel (this header: modified DH + Hayati beta, the parameter
// vector and names, templated forward kinematics, autodiff Jacobians, IK); damped_least_squares.h (the IK's
// damped least-squares loop, shared with the planner's candidate pool); dh_table.h (a model as a standard,
// modified or modified_hayati DH table when exact, else the reasons and their cost); joint_motion.h.
// Uses geometry, base; Ceres (Jets).
//
// Serial-arm kinematic model and its identification parameterisation.
//
// Convention (../shared/DESIGN.md section 4). Joint i (1-based) is revolute about the z axis of its own frame and
// its link transform is modified DH (Craig) with a Hayati tilt beta:
//
//   link_{i-1}_from_link_i(q_i) = RotX(alpha_i) * TransX(a_i) * RotY(beta_i) * RotZ(q_i + theta_i) * TransZ(d_i)
//
// With beta the model is complete and parametrically continuous: a small tilt between nominally parallel
// axes (PUMA joints 2-3, UR joints 2-3-4) is a small beta, not the huge d offsets of plain DH (K2).
// Redundant parameters (beta on non-parallel pairs, d on parallel pairs, the base, ...) are found and
// fixed by the rank analysis of identification/identifiability.h, never by assumption.
//
// Frame chain, with the base and camera as corrections of their nominal transforms:
//
//   base_from_cam(q; rho) = base_from_link0 * Exp(base correction)
//                           * prod_i link_{i-1}_from_link_i(q_i)
//                           * link_n_from_flange                      (constant, from the DH table)
//                           * flange_from_cam * Exp(cam correction)
//
// A fixed camera looking at points carried by the flange (eye-to-hand, RobotModel::mount) swaps the roles:
//
//   base_from_cam(rho)       = base_from_cam * Exp(cam correction)              (RobotModel::base_from_cam)
//   points_from_cam(q; rho)  = base_from_flange(q; rho)^-1 * base_from_cam(rho)  (points: the flange frame)
//
// where base_from_flange is the chain above up to the flange (flange_from_cam takes no part). The points'
// frame is the base in eye-in-hand and the flange in eye-to-hand: PointsFromCam is the camera in it, the
// pose every projection of the unknown points goes through.
//
// Parameter vector rho (SI units: m and rad), for n joints, size 5n + 12:
//   [0, 6)            base correction: tx ty tz (m), rx ry rz (rotation vector, rad)
//   [6 + 5(i-1), +5)  joint i: alpha, a, beta, theta, d
//   [6 + 5n, +6)      camera correction: tx ty tz, rx ry rz
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"

namespace selfcal {

struct LinkParameters {
  double alpha = 0;  // rad
  double a = 0;      // m
  double beta = 0;   // rad (Hayati tilt about y)
  double theta = 0;  // rad, joint offset
  double d = 0;      // m
};

struct JointLimits {
  double min_rad = -kPi;
  double max_rad = kPi;
};

// A row of a DH table as written in robot configs (SI units).
struct DhRow {
  double a = 0, alpha = 0, d = 0, theta = 0;
};
enum class DhConvention { kStandard, kModified };

// Where the camera is: on the flange, looking at points fixed in the base frame (eye-in-hand), or fixed in
// the base frame, looking at points carried by the flange (eye-to-hand).
enum class CameraMount { kEyeInHand, kEyeToHand };
// "eye_in_hand", "eye_to_hand": the names files and reports use.
const char* CameraMountName(CameraMount mount);
// False (mount untouched) for any other text.
bool ParseCameraMount(const std::string& text, CameraMount* mount);

struct RobotModel {
  std::string name;
  std::vector<LinkParameters> links;  // nominal, one per joint
  std::vector<JointLimits> limits;
  Rigid3 base_from_link0;             // nominal base transform
  Rigid3 link_n_from_flange;          // constant tail of the DH table
  Rigid3 flange_from_cam;             // nominal hand-eye transform (eye-in-hand)
  CameraMount mount = CameraMount::kEyeInHand;
  Rigid3 base_from_cam;               // nominal fixed camera (eye-to-hand; unused in eye-in-hand)

  int num_joints() const { return static_cast<int>(links.size()); }
  int num_parameters() const { return 5 * num_joints() + 12; }

  // Builds the model from a DH table. Standard DH rows are Rz(q+theta) Tz(d) Tx(a) Rx(alpha) and are
  // regrouped exactly into the modified form above; the last row's Tx(a) Rx(alpha) becomes
  // link_n_from_flange. Modified rows are Rx(alpha) Tx(a) Rz(q+theta) Tz(d).
  static RobotModel FromDh(const std::string& name, DhConvention convention, const std::vector<DhRow>& rows,
                           const std::vector<JointLimits>& limits, const Rigid3& base_from_link0,
                           const Rigid3& flange_from_cam);

  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

enum class ParameterKind { kLength, kAngle };

// Names and layout of rho for a model.
class KinematicParameters {
 public:
  explicit KinematicParameters(int num_joints);

  int size() const { return static_cast<int>(names_.size()); }
  int num_joints() const { return num_joints_; }
  const std::vector<std::string>& names() const { return names_; }
  const std::string& name(int index) const { return names_.at(index); }
  ParameterKind kind(int index) const { return kinds_.at(index); }
  // -1 when no parameter has that name.
  int IndexOf(const std::string& name) const;

  static int BaseOffset() { return 0; }
  static int JointOffset(int joint0) { return 6 + 5 * joint0; }  // joint0 is 0-based
  int CamOffset() const { return 6 + 5 * num_joints_; }

  // rho at the nominal model: zero corrections, nominal link parameters.
  static Eigen::VectorXd Nominal(const RobotModel& model);

 private:
  int num_joints_;
  std::vector<std::string> names_;
  std::vector<ParameterKind> kinds_;
};

// Applies rho to a copy of the model: the result's nominal values are the parameterised ones (so that
// Nominal(result) differs from rho only by zero corrections).
RobotModel ApplyParameters(const RobotModel& model, const Eigen::VectorXd& rho);

// Forward kinematics, templated for autodiff through rho and q.
template <typename T>
Rigid3T<T> LinkTransform(const T& alpha, const T& a, const T& beta, const T& theta_total, const T& d) {
  const Mat3T<T> r = RotX(alpha) * RotY(beta) * RotZ(theta_total);
  // Rx(alpha) Tx(a) Ry(beta) Rz(.) Tz(d): translation = Rx(alpha) [a,0,0] + Rx(alpha) Ry(beta) Rz(.) [0,0,d]
  const Vec3T<T> t = RotX(alpha) * Vec3T<T>(a, T(0), T(0)) + r * Vec3T<T>(T(0), T(0), d);
  return Rigid3T<T>(r, t);
}

template <typename T>
Rigid3T<T> BaseFromFlange(const RobotModel& model, const T* rho, const T* q) {
  Rigid3T<T> chain = model.base_from_link0.Cast<T>() * RigidFromTranslationRotvec(rho);
  for (int i = 0; i < model.num_joints(); ++i) {
    const T* p = rho + KinematicParameters::JointOffset(i);
    chain = chain * LinkTransform<T>(p[0], p[1], p[2], q[i] + p[3], p[4]);
  }
  return chain * model.link_n_from_flange.Cast<T>();
}

// The camera in the base frame: through the arm (eye-in-hand), or the fixed camera (eye-to-hand, q unused).
template <typename T>
Rigid3T<T> BaseFromCam(const RobotModel& model, const T* rho, const T* q) {
  const T* cam = rho + 6 + 5 * model.num_joints();
  if (model.mount == CameraMount::kEyeToHand) return model.base_from_cam.Cast<T>() * RigidFromTranslationRotvec(cam);
  return BaseFromFlange(model, rho, q) * model.flange_from_cam.Cast<T>() * RigidFromTranslationRotvec(cam);
}

// The camera in the frame of the unknown points: BaseFromCam (eye-in-hand), the flange from the fixed camera
// (eye-to-hand).
template <typename T>
Rigid3T<T> PointsFromCam(const RobotModel& model, const T* rho, const T* q) {
  if (model.mount == CameraMount::kEyeInHand) return BaseFromCam(model, rho, q);
  return BaseFromFlange(model, rho, q).Inverse() * BaseFromCam(model, rho, q);
}

// The camera of a pose whose flange pose was recorded by the controller (data without joint angles):
//   base_from_cam = base_from_link0 * Exp(base correction) * base_from_flange * flange_from_cam * Exp(cam)
// with the camera correction at rho[CamOffset()]; the link parameters of rho take no part.
template <typename T>
Rigid3T<T> BaseFromCamGivenFlange(const RobotModel& model, const T* rho, const Rigid3& base_from_flange) {
  const T* cam = rho + 6 + 5 * model.num_joints();
  return model.base_from_link0.Cast<T>() * RigidFromTranslationRotvec(rho) * base_from_flange.Cast<T>() *
         model.flange_from_cam.Cast<T>() * RigidFromTranslationRotvec(cam);
}

// PointsFromCam of a pose whose flange pose was recorded: BaseFromCamGivenFlange (eye-in-hand); for
// eye-to-hand (base_from_link0 * Exp(base correction) * base_from_flange)^-1 * base_from_cam * Exp(cam).
template <typename T>
Rigid3T<T> PointsFromCamGivenFlange(const RobotModel& model, const T* rho, const Rigid3& base_from_flange) {
  if (model.mount == CameraMount::kEyeInHand) return BaseFromCamGivenFlange(model, rho, base_from_flange);
  const T* cam = rho + 6 + 5 * model.num_joints();
  const Rigid3T<T> flange_in_base =
      model.base_from_link0.Cast<T>() * RigidFromTranslationRotvec(rho) * base_from_flange.Cast<T>();
  return flange_in_base.Inverse() * model.base_from_cam.Cast<T>() * RigidFromTranslationRotvec(cam);
}

// Double convenience overloads.
Rigid3 BaseFromFlange(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q);
Rigid3 BaseFromCam(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q);
Rigid3 PointsFromCam(const RobotModel& model, const Eigen::VectorXd& rho, const Eigen::VectorXd& q);

// Pairs (i, i+1), 1-based joint numbers, whose axes are parallel at the nominal model (|sin alpha| and
// |beta| below tol): the places where plain DH would be singular.
std::vector<int> ParallelAxisPairs(const RobotModel& model, double tol = 1e-9);

// Numeric inverse kinematics on the nominal model (damped least squares from `seed`): joint angles that
// put the camera at base_from_cam_target. Returns false if it does not converge to 1e-10.
bool SolveCameraIk(const RobotModel& model, const Eigen::VectorXd& rho, const Rigid3& base_from_cam_target,
                   const Eigen::VectorXd& seed, Eigen::VectorXd* q);

// Multiplies every length of the model and of rho by s (angles unchanged): the model then predicts the
// same rotations and translations multiplied by s. Used when the yardstick fixes the metric scale.
void ScaleLengths(double s, RobotModel* model, Eigen::VectorXd* rho);

bool WithinLimits(const RobotModel& model, const Eigen::VectorXd& q, double margin_rad = 0.0);

}  // namespace selfcal
