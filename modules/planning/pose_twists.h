// Derivatives of the camera pose with respect to every kinematic parameter, as spatial twists, templated
// on the scalar so that the joint angles can be Jets (the planner differentiates these derivatives with
// respect to the joints: eq. (39) and Cond(J) are functions of the identification Jacobian).
//
// For base_from_cam(q; rho) = A * Exp(eps * xi_local) * B (robot_model.h), a change of one parameter
// moves the camera by the spatial twist xi = Ad_A xi_local, expressed in the base frame:
//   rotation about a unit axis e (in frame A) through A's origin:  omega = R_A e,  v = t_A x omega
//   translation along e (in frame A):                               omega = 0,     v = R_A e
// and then   d R / d rho_k = [omega_k]x R,   d p / d rho_k = omega_k x p + v_k   (p = camera centre).
// Parameters in the chain order of robot_model.h: base correction (tx ty tz rx ry rz about link0), per
// joint alpha (x), a (x), beta (y), theta (z), d (z), camera correction (tx ty tz rx ry rz about cam).
//
// Valid at zero base and camera corrections (the nominal rho of the model): the planner works on the
// nominal model, or on a calibrated one with its corrections folded in (ApplyParameters).
//
// Relative pose of pose i to the reference pose r (the measurement of the paper's pipeline),
// cam_r_from_cam_i: its rho-derivative in the reference camera frame is R_r^T [dw ; dw x p_i + dv] with
// dw = omega_k(q_i) - omega_k(q_r), dv = v_k(q_i) - v_k(q_r). Rotating each 3-row group by its own
// orthogonal matrix does not change singular values, so Cond(J) can be taken on [dw ; dw x p_i + dv].
//
// Eye-to-hand (RobotModel::mount): the camera that matters is the fixed one seen from the flange, the frame
// of the points, X = F^-1 B (F = base_from_flange(q), B = the fixed camera): "base" below is then the flange
// frame and base_from_cam is X (PointsFromCam). A chain parameter moves F by its spatial twist xi (base
// frame), so dX = -[Ad_{F^-1} xi] X: its twist in the flange frame is -Ad_{F^-1} xi, with
// Ad_G (omega, v) = (R_G omega, t_G x R_G omega + R_G v). The camera correction turns and shifts X about its
// own axes, as the eye-in-hand camera correction does.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::planning {

// The most joints the planner differentiates for: its Jets over the joint angles have a fixed size.
constexpr int kMaxJoints = 7;

}  // namespace selfcal::planning

namespace selfcal::planning::internal {

template <typename T>
struct CameraTwists {
  Rigid3T<T> base_from_cam;
  std::vector<Vec3T<T>> omega, v;  // per rho index, base frame
};

// Eye-to-hand: a spatial twist of the flange in the base frame as the twist of X = F^-1 B in the flange frame,
// -Ad_{F^-1} (omega, v), in place.
template <typename T>
void FlangeTwistToPointsFrame(const Rigid3T<T>& base_from_flange, Vec3T<T>* omega, Vec3T<T>* v) {
  const Mat3T<T> rt = base_from_flange.rotation.transpose();
  const Vec3T<T> t = -(rt * base_from_flange.translation);
  const Vec3T<T> w = rt * *omega;
  *v = -(t.cross(w) + rt * *v);
  *omega = -w;
}

template <typename T>
CameraTwists<T> ComputeCameraTwists(const RobotModel& model, const T* q) {
  const int n = model.num_joints();
  CameraTwists<T> out;
  out.omega.assign(model.num_parameters(), Vec3T<T>::Zero());
  out.v.assign(model.num_parameters(), Vec3T<T>::Zero());
  const Vec3T<T> ex(T(1), T(0), T(0)), ey(T(0), T(1), T(0)), ez(T(0), T(0), T(1));
  const Vec3T<T> axes[3] = {ex, ey, ez};
  auto rotation = [&out](int k, const Rigid3T<T>& frame, const Vec3T<T>& axis) {
    out.omega[k] = frame.rotation * axis;
    out.v[k] = frame.translation.cross(out.omega[k]);
  };
  auto translation = [&out](int k, const Rigid3T<T>& frame, const Vec3T<T>& axis) {
    out.v[k] = frame.rotation * axis;
  };
  Rigid3T<T> f = model.base_from_link0.Cast<T>();
  for (int k = 0; k < 3; ++k) {
    translation(k, f, axes[k]);
    rotation(3 + k, f, axes[k]);
  }
  for (int i = 0; i < n; ++i) {
    const LinkParameters& p = model.links[i];
    const int off = KinematicParameters::JointOffset(i);
    rotation(off + 0, f, ex);
    f = f * Rigid3T<T>::FromRotation(RotX(T(p.alpha)));
    translation(off + 1, f, ex);
    f = f * Rigid3T<T>::FromTranslation(Vec3T<T>(T(p.a), T(0), T(0)));
    rotation(off + 2, f, ey);
    f = f * Rigid3T<T>::FromRotation(RotY(T(p.beta)));
    rotation(off + 3, f, ez);
    f = f * Rigid3T<T>::FromRotation(RotZ(q[i] + T(p.theta)));
    translation(off + 4, f, ez);
    f = f * Rigid3T<T>::FromTranslation(Vec3T<T>(T(0), T(0), T(p.d)));
  }
  const int cam = 6 + 5 * n;
  if (model.mount == CameraMount::kEyeToHand) {
    const Rigid3T<T> flange = f * model.link_n_from_flange.Cast<T>();
    for (int k = 0; k < cam; ++k) FlangeTwistToPointsFrame(flange, &out.omega[k], &out.v[k]);
    f = flange.Inverse() * model.base_from_cam.Cast<T>();
  } else {
    f = f * model.link_n_from_flange.Cast<T>() * model.flange_from_cam.Cast<T>();
  }
  for (int k = 0; k < 3; ++k) {
    translation(cam + k, f, axes[k]);
    rotation(cam + 3 + k, f, axes[k]);
  }
  out.base_from_cam = f;
  return out;
}

// The camera pose and the spatial twists of the joint angles alone (theta_j moves the camera as q_j does):
// omega.col(j), v.col(j), resized to the joint count. The same frames and products as ComputeCameraTwists, so
// the same values to the bit, without the other parameters' twists (the candidate pool's inverse kinematics
// and eq. (39)'s barrier need only these).
template <typename T>
Rigid3T<T> ComputeJointTwists(const RobotModel& model, const T* q, Eigen::Matrix<T, 3, Eigen::Dynamic>* omega,
                              Eigen::Matrix<T, 3, Eigen::Dynamic>* v) {
  const int n = model.num_joints();
  omega->resize(3, n);
  v->resize(3, n);
  const Vec3T<T> ez(T(0), T(0), T(1));
  Rigid3T<T> f = model.base_from_link0.Cast<T>();
  for (int i = 0; i < n; ++i) {
    const LinkParameters& p = model.links[i];
    f = f * Rigid3T<T>::FromRotation(RotX(T(p.alpha)));
    f = f * Rigid3T<T>::FromTranslation(Vec3T<T>(T(p.a), T(0), T(0)));
    f = f * Rigid3T<T>::FromRotation(RotY(T(p.beta)));
    const Vec3T<T> w = f.rotation * ez;
    omega->col(i) = w;
    v->col(i) = f.translation.cross(w);
    f = f * Rigid3T<T>::FromRotation(RotZ(q[i] + T(p.theta)));
    f = f * Rigid3T<T>::FromTranslation(Vec3T<T>(T(0), T(0), T(p.d)));
  }
  if (model.mount == CameraMount::kEyeToHand) {
    const Rigid3T<T> flange = f * model.link_n_from_flange.Cast<T>();
    for (int j = 0; j < n; ++j) {
      Vec3T<T> w = omega->col(j), u = v->col(j);
      FlangeTwistToPointsFrame(flange, &w, &u);
      omega->col(j) = w;
      v->col(j) = u;
    }
    return flange.Inverse() * model.base_from_cam.Cast<T>();
  }
  return f * model.link_n_from_flange.Cast<T>() * model.flange_from_cam.Cast<T>();
}

}  // namespace selfcal::planning::internal
