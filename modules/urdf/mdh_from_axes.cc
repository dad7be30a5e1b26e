// The classic conversion of joint axis lines to modified DH (Craig) with Hayati's beta:
// frame link_k has its z axis on joint k's axis (link_0's on joint 1's) and its x axis on the common
// normal from axis k to axis k+1; where the two axes are (nearly) parallel the common normal is not
// unique, and the one through the point where the previous normal meets axis k is taken (d = 0) with the
// residual tilt as beta. Every link transform is then exactly RotX(alpha) TransX(a) RotY(beta) RotZ(theta)
// TransZ(d), and the chain's forward kinematics is the product of the joints' rotations about their lines.
#include <cmath>

#include "urdf/urdf_chain.h"

namespace selfcal::urdf {
namespace {

// Axes whose directions differ by less than this sine (about 5.7 deg) take Hayati's beta instead of a
// common normal: for a tilt eps towards the normal, the common normal's foot moves by about a / eps along
// the axis (43 m for the PUMA's a2 at 0.01 rad), the offsets the beta is there to avoid.
constexpr double kParallelSine = 0.1;

struct Frame {
  Eigen::Vector3d origin, x, z;
  Rigid3 Rigid() const {
    Eigen::Matrix3d r;
    r.col(0) = x;
    r.col(1) = z.cross(x);
    r.col(2) = z;
    return Rigid3(r, origin);
  }
};

// A unit vector perpendicular to z, as close to `hint` as possible (another axis when hint is along z).
Eigen::Vector3d PerpendicularTo(const Eigen::Vector3d& z, const Eigen::Vector3d& hint) {
  for (const Eigen::Vector3d& h : {hint, Eigen::Vector3d::UnitX().eval(), Eigen::Vector3d::UnitY().eval()}) {
    const Eigen::Vector3d p = h - h.dot(z) * z;
    if (p.norm() > 1e-6) return p.normalized();
  }
  return Eigen::Vector3d::UnitZ();
}

// The frame on axis `a` whose x axis meets axis `b`; `foot` is where the previous x axis meets axis a.
Frame NormalFrame(const AxisLine& a, const AxisLine& b, const Eigen::Vector3d& foot, const Eigen::Vector3d& x_hint,
                  Eigen::Vector3d* next_foot) {
  Frame f;
  f.z = a.direction;
  const Eigen::Vector3d c = a.direction.cross(b.direction);
  Eigen::Vector3d hit;
  if (c.norm() < kParallelSine) {
    f.origin = foot;
    // The point of axis b in the plane through foot perpendicular to axis a.
    const double s = -(b.point - foot).dot(a.direction) / b.direction.dot(a.direction);
    hit = b.point + s * b.direction;
  } else {
    const Eigen::Vector3d w0 = a.point - b.point;
    const double bb = a.direction.dot(b.direction), d = a.direction.dot(w0), e = b.direction.dot(w0);
    const double denom = 1 - bb * bb;
    f.origin = a.point + ((bb * e - d) / denom) * a.direction;
    hit = b.point + ((e - bb * d) / denom) * b.direction;
  }
  const Eigen::Vector3d normal = hit - f.origin;
  f.x = normal.norm() > 1e-12 ? Eigen::Vector3d(normal.normalized())
                              : PerpendicularTo(f.z, c.norm() > 1e-12 ? c : x_hint);
  *next_foot = hit;
  return f;
}

// alpha, a, beta, theta, d of prev_from_next = RotX(alpha) TransX(a) RotY(beta) RotZ(theta) TransZ(d).
LinkParameters ParametersOf(const Rigid3& prev_from_next) {
  const Eigen::Vector3d v = prev_from_next.rotation.col(2);
  LinkParameters p;
  p.beta = std::asin(std::clamp(v.x(), -1.0, 1.0));
  p.alpha = std::atan2(-v.y(), v.z());
  const Eigen::Matrix3d rz = (RotX(p.alpha) * RotY(p.beta)).transpose() * prev_from_next.rotation;
  p.theta = std::atan2(rz(1, 0), rz(0, 0));
  const Eigen::Vector3d& t = prev_from_next.translation;
  const double cb2 = v.y() * v.y() + v.z() * v.z();
  p.d = (t.y() * v.y() + t.z() * v.z()) / cb2;
  p.a = t.x() - p.d * v.x();
  return p;
}

}  // namespace

RobotModel ModelFromAxes(const UrdfChain& chain, const Rigid3& flange_from_cam) {
  const std::vector<AxisLine>& axes = chain.axes;
  const int n = static_cast<int>(axes.size());
  std::vector<Frame> frames(static_cast<size_t>(n) + 1);
  // link_0: on axis 1, at the base origin's foot, x as close to the base's x as possible.
  const Eigen::Vector3d base_foot = axes[0].point + (-axes[0].point).dot(axes[0].direction) * axes[0].direction;
  frames[0] = Frame{base_foot, PerpendicularTo(axes[0].direction, Eigen::Vector3d::UnitX()), axes[0].direction};
  Eigen::Vector3d foot = base_foot;
  for (int k = 0; k + 1 < n; ++k) {
    Eigen::Vector3d next_foot;
    frames[k + 1] = NormalFrame(axes[k], axes[k + 1], foot, frames[k].x, &next_foot);
    foot = next_foot;
  }
  // link_n: on the last axis at the foot of the previous normal, x as close to the tip's x as possible.
  const Eigen::Vector3d tip_x = chain.base_from_tip.rotation.col(0);
  frames[n] = Frame{foot, PerpendicularTo(axes[n - 1].direction, tip_x), axes[n - 1].direction};

  RobotModel model;
  model.name = chain.robot_name;
  model.base_from_link0 = frames[0].Rigid();
  for (int k = 0; k < n; ++k) {
    model.links.push_back(ParametersOf(frames[k].Rigid().Inverse() * frames[k + 1].Rigid()));
    model.limits.push_back(axes[k].limits);
  }
  model.link_n_from_flange = frames[n].Rigid().Inverse() * chain.base_from_tip;
  model.flange_from_cam = chain.tip_from_camera ? *chain.tip_from_camera : flange_from_cam;
  return model;
}

}  // namespace selfcal::urdf
