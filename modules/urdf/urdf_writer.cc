#include "urdf/urdf_writer.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "base/atomic_file.h"

namespace selfcal::urdf {
namespace {

// |R(2,0)| above this: roll and yaw would be ill-conditioned, the origin goes through an intermediate link.
constexpr double kNearGimbalLock = 0.7;

std::string Num(double v) {
  if (std::abs(v) < 1e-15) return "0";  // rounding residue (1e-19 m) of a composed transform: noise to a reader
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// Names in attributes: the XML special characters escaped.
std::string Xml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string OriginElement(const Rigid3& t) {
  const Eigen::Matrix3d& r = t.rotation;
  // R = Rz(yaw) Ry(pitch) Rx(roll); at gimbal lock (a right-angle pitch) yaw = 0 and roll takes the rest.
  const double cos_pitch = std::hypot(r(2, 1), r(2, 2));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  const bool locked = cos_pitch < 1e-12;
  const double roll = locked ? std::atan2(-r(1, 2), r(1, 1)) : std::atan2(r(2, 1), r(2, 2));
  const double yaw = locked ? 0.0 : std::atan2(r(1, 0), r(0, 0));
  return "<origin xyz=\"" + Num(t.translation.x()) + " " + Num(t.translation.y()) + " " + Num(t.translation.z()) +
         "\" rpy=\"" + Num(roll) + " " + Num(pitch) + " " + Num(yaw) + "\"/>";
}

namespace {

class UrdfText {
 public:
  void Link(const std::string& name) { out_ << "  <link name=\"" << Xml(name) << "\"/>\n"; }

  // A joint from parent to child at `origin`; revolute about z within `limits` when given, else fixed.
  void Joint(const std::string& name, const std::string& parent, const std::string& child, const Rigid3& origin,
             const JointLimits* limits, double velocity_rad_s = 0) {
    std::string from = parent;
    Rigid3 last = origin;
    if (std::abs(origin.rotation(2, 0)) > kNearGimbalLock) {
      const Rigid3 quarter = Rigid3::FromRotation(RotZ(kPi / 2));
      from = name + "_origin";
      Link(from);
      Write(name + "_origin", "fixed", parent, from, origin * quarter, nullptr, 0);
      last = quarter.Inverse();
    }
    Write(name, limits ? "revolute" : "fixed", from, child, last, limits, velocity_rad_s);
  }

  std::string str() const { return out_.str(); }

 private:
  void Write(const std::string& name, const char* type, const std::string& parent, const std::string& child,
             const Rigid3& origin, const JointLimits* limits, double velocity_rad_s) {
    out_ << "  <joint name=\"" << Xml(name) << "\" type=\"" << type << "\">\n    <parent link=\"" << Xml(parent)
         << "\"/>\n    <child link=\"" << Xml(child) << "\"/>\n    " << OriginElement(origin) << "\n";
    if (limits) {
      out_ << "    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"" << Num(limits->min_rad) << "\" upper=\""
           << Num(limits->max_rad) << "\" effort=\"0\" velocity=\"" << Num(velocity_rad_s) << "\"/>\n";
    }
    out_ << "  </joint>\n";
  }

  std::ostringstream out_;
};

}  // namespace

Result<std::string> UrdfOfModel(const RobotModel& model, const UrdfNames& names, const FkCheckOptions& check) {
  const int n = model.num_joints();
  for (const size_t given : {names.joints.size(), names.links.size(), names.velocities_rad_s.size()}) {
    if (given != 0 && static_cast<int>(given) != n) {
      return Status::Error(ErrorCode::kInternal,
                           std::to_string(given) + " joint names, links or velocities for " + std::to_string(n) + " joints");
    }
  }
  UrdfText text;
  text.Link(names.base_link);
  text.Link("link0");
  text.Joint("base_link_to_link0", names.base_link, "link0", model.base_from_link0, nullptr);
  std::string parent = "link0";
  for (int i = 0; i < n; ++i) {
    const LinkParameters& p = model.links[i];
    const std::string link = names.links.empty() ? "link" + std::to_string(i + 1) : names.links[i];
    text.Link(link);
    text.Joint(names.joints.empty() ? "joint" + std::to_string(i + 1) : names.joints[i], parent, link,
               LinkTransform<double>(p.alpha, p.a, p.beta, p.theta, p.d), &model.limits[i],
               names.velocities_rad_s.empty() ? kDefaultJointVelocityRadPerS : names.velocities_rad_s[i]);
    parent = link;
  }
  text.Link(names.tip_link);
  text.Joint(parent + "_to_" + names.tip_link, parent, names.tip_link, model.link_n_from_flange, nullptr);
  text.Link(names.camera_link);
  if (model.mount == CameraMount::kEyeToHand) {  // the camera fixed in the base frame
    text.Joint(names.base_link + "_to_" + names.camera_link, names.base_link, names.camera_link, model.base_from_cam,
               nullptr);
  } else {
    text.Joint(names.tip_link + "_to_" + names.camera_link, names.tip_link, names.camera_link, model.flange_from_cam,
               nullptr);
  }
  const std::string robot = names.robot.empty() ? model.name : names.robot;
  const std::string urdf =
      "<?xml version=\"1.0\"?>\n<!-- Written by selfcal (docs/urdf.md): modified DH + Hayati, "
      "link_i is the model's frame of link i; " +
      names.camera_link + " is the camera's optical frame (z forward, x right, y down). -->\n" + "<robot name=\"" +
      Xml(robot) + "\">\n" + text.str() + "</robot>\n";
  Result<FkCheck> compared =
      CompareWithKdl(urdf, "the written URDF", {names.base_link, names.tip_link, names.camera_link}, model, check);
  if (!compared.ok()) return Status::Error(ErrorCode::kInternal, compared.status().message());
  return urdf;
}

Status WriteUrdf(const RobotModel& model, const UrdfNames& names, const std::string& path) {
  Result<std::string> text = UrdfOfModel(model, names);
  if (!text.ok()) return text.status();
  return WriteFileAtomically(path, *text);
}

}  // namespace selfcal::urdf
