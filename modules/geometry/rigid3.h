// Module geometry (ARCHITECTURE.md): Rigid3T<T> (b_from_a), rotations, SO(3) exp/log. Uses Eigen and base (kPi).
//
// Rigid transforms and rotations, templated on the scalar so that Ceres Jets flow through them.
//
// Naming: a transform `b_from_a` maps coordinates of a point in frame a to frame b:
//   p_in_b = b_from_a * p_in_a,   c_from_a = c_from_b * b_from_a.
// Rotation vectors (axis * angle, radians) parameterise small corrections; Exp/Log convert.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "base/numbers.h"

namespace selfcal {

template <typename T>
using Vec3T = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat3T = Eigen::Matrix<T, 3, 3>;

template <typename T>
Mat3T<T> Skew(const Vec3T<T>& v) {
  Mat3T<T> s;
  s << T(0), -v.z(), v.y(), v.z(), T(0), -v.x(), -v.y(), v.x(), T(0);
  return s;
}

// d p / d (v, omega) of a point p in a frame moved by the small motion p -> p + omega x p + v: [I, -[p]x]
// (the pose-error columns of the bundle's error model and of the held-out test).
inline Eigen::Matrix<double, 3, 6> SmallMotionJacobian(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 3, 6> j;
  j.leftCols<3>().setIdentity();
  j.rightCols<3>() = -Skew<double>(p);
  return j;
}

template <typename T>
Mat3T<T> RotX(const T& angle) {
  using std::cos;
  using std::sin;
  const T c = cos(angle), s = sin(angle);
  Mat3T<T> r;
  r << T(1), T(0), T(0), T(0), c, -s, T(0), s, c;
  return r;
}

template <typename T>
Mat3T<T> RotY(const T& angle) {
  using std::cos;
  using std::sin;
  const T c = cos(angle), s = sin(angle);
  Mat3T<T> r;
  r << c, T(0), s, T(0), T(1), T(0), -s, T(0), c;
  return r;
}

template <typename T>
Mat3T<T> RotZ(const T& angle) {
  using std::cos;
  using std::sin;
  const T c = cos(angle), s = sin(angle);
  Mat3T<T> r;
  r << c, -s, T(0), s, c, T(0), T(0), T(0), T(1);
  return r;
}

// Rodrigues' formula; exact (Taylor) near zero so derivatives stay finite for Jets at w = 0.
template <typename T>
Mat3T<T> ExpSO3(const Vec3T<T>& w) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = w.squaredNorm();
  const Mat3T<T> k = Skew(w);
  T a, b;
  if (theta2 < T(1e-12)) {
    a = T(1) - theta2 / T(6);
    b = T(0.5) - theta2 / T(24);
  } else {
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1) - cos(theta)) / theta2;
  }
  return Mat3T<T>::Identity() + a * k + b * k * k;
}

// Rotation vector of a rotation matrix (double only), angle in [0, pi].
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& r);

// Angle of a rotation matrix in [0, pi] (double only); robust near 0 and pi.
double RotationAngle(const Eigen::Matrix3d& r);

// Projects a near-rotation matrix onto SO(3) (closest in Frobenius norm).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);

template <typename T>
struct Rigid3T {
  Mat3T<T> rotation = Mat3T<T>::Identity();
  Vec3T<T> translation = Vec3T<T>::Zero();

  Rigid3T() = default;
  Rigid3T(const Mat3T<T>& r, const Vec3T<T>& t) : rotation(r), translation(t) {}

  static Rigid3T Identity() { return Rigid3T(); }
  static Rigid3T FromTranslation(const Vec3T<T>& t) { return Rigid3T(Mat3T<T>::Identity(), t); }
  static Rigid3T FromRotation(const Mat3T<T>& r) { return Rigid3T(r, Vec3T<T>::Zero()); }

  Rigid3T Inverse() const {
    const Mat3T<T> rt = rotation.transpose();
    return Rigid3T(rt, -(rt * translation));
  }
  Vec3T<T> operator*(const Vec3T<T>& p) const { return rotation * p + translation; }
  Rigid3T operator*(const Rigid3T& other) const {
    return Rigid3T(rotation * other.rotation, rotation * other.translation + translation);
  }
  template <typename U>
  Rigid3T<U> Cast() const {
    return Rigid3T<U>(rotation.template cast<U>(), translation.template cast<U>());
  }
  Eigen::Matrix<T, 4, 4> Matrix() const {
    Eigen::Matrix<T, 4, 4> m = Eigen::Matrix<T, 4, 4>::Identity();
    m.template topLeftCorner<3, 3>() = rotation;
    m.template topRightCorner<3, 1>() = translation;
    return m;
  }
};

using Rigid3 = Rigid3T<double>;

// Rigid3 from a 6-vector (tx, ty, tz, rx, ry, rz): translation then rotation vector.
template <typename T>
Rigid3T<T> RigidFromTranslationRotvec(const T* v) {
  return Rigid3T<T>(ExpSO3<T>(Vec3T<T>(v[3], v[4], v[5])), Vec3T<T>(v[0], v[1], v[2]));
}

// Position and orientation difference between two transforms: ||t_a - t_b|| (m) and the angle of
// R_a^T R_b (rad).
struct PoseDifference {
  double position_m = 0;
  double rotation_rad = 0;
};
PoseDifference ComparePoses(const Rigid3& a, const Rigid3& b);

constexpr double kMmPerM = 1e3;  // reports and configs speak mm (docs/frames-and-units.md)
constexpr double DegToRad(double deg) { return deg * kPi / 180.0; }
constexpr double RadToDeg(double rad) { return rad * 180.0 / kPi; }

}  // namespace selfcal
