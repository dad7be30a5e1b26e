#include "urdf/urdf_robot.h"

#include <cstdio>
#include <random>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <urdf_model/model.h>

#include "base/atomic_file.h"
#include "urdf/kdl_chain.h"
#include "urdf/urdf_chain.h"
#include "urdf/urdf_parse.h"
#include "urdf/urdf_writer.h"

namespace selfcal::urdf {
namespace {

Rigid3 RigidOf(const KDL::Frame& f) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = f.M(i, j);
  }
  return Rigid3(r, Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()));
}

std::string Format(const char* fmt, double a, double b) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, fmt, a, b);
  return buffer;
}

std::string JointsDeg(const Eigen::VectorXd& q) {
  std::string out;
  for (int i = 0; i < q.size(); ++i) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%s%.6g", i ? ", " : "", RadToDeg(q[i]));
    out += buffer;
  }
  return "[" + out + "] deg";
}

}  // namespace

Result<FkCheck> CompareWithKdl(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                               const RobotModel& model, const FkCheckOptions& options) {
  const std::vector<Eigen::VectorXd> joints = RandomJointsWithinLimits(model, options.samples, options.seed);
  Result<std::vector<Rigid3>> tips = KdlChainPoses(text, name, spec.base_link, spec.tip_link, joints);
  if (!tips.ok()) return tips.status();
  Result<std::vector<Rigid3>> cams = tips;
  if (!spec.camera_link.empty()) {
    // A fixed camera (eye-to-hand) hangs from the base: its chain has no joints.
    const bool fixed = model.mount == CameraMount::kEyeToHand;
    cams = KdlChainPoses(text, name, spec.base_link, spec.camera_link,
                         fixed ? std::vector<Eigen::VectorXd>(joints.size(), Eigen::VectorXd()) : joints);
  }
  if (!cams.ok()) return cams.status();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  FkCheck check;
  check.samples = static_cast<int>(joints.size());
  double worst = -1;
  for (size_t i = 0; i < joints.size(); ++i) {
    PoseDifference diff = ComparePoses(BaseFromFlange(model, rho, joints[i]), (*tips)[i]);
    if (!spec.camera_link.empty()) {
      const PoseDifference cam = ComparePoses(BaseFromCam(model, rho, joints[i]), (*cams)[i]);
      diff.position_m = std::max(diff.position_m, cam.position_m);
      diff.rotation_rad = std::max(diff.rotation_rad, cam.rotation_rad);
    }
    const double score = std::max(diff.position_m / options.tolerance_m, diff.rotation_rad / options.tolerance_rad);
    if (score > worst) {
      worst = score;
      check.worst_sample = static_cast<int>(i);
      check.worst_q = joints[i];
      check.worst_position_m = diff.position_m;
      check.worst_rotation_rad = diff.rotation_rad;
    }
  }
  if (worst > 1) {
    return Status::Error(ErrorCode::kInvalidInput,
                         name + ": the converted model's forward kinematics differs from KDL's by " +
                             Format("%.3g m / %.3g rad", check.worst_position_m, check.worst_rotation_rad) +
                             " at joints " + JointsDeg(check.worst_q) + " (random sample " +
                             std::to_string(check.worst_sample + 1) + " of " + std::to_string(check.samples) +
                             Format(", tolerance %.3g m / %.3g rad)", options.tolerance_m, options.tolerance_rad));
  }
  return check;
}

std::vector<Eigen::VectorXd> RandomJointsWithinLimits(const RobotModel& model, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Eigen::VectorXd> out;
  for (int s = 0; s < count; ++s) {
    Eigen::VectorXd q(model.num_joints());
    for (int j = 0; j < model.num_joints(); ++j) {
      std::uniform_real_distribution<double> u(model.limits[j].min_rad, model.limits[j].max_rad);
      q[j] = u(rng);
    }
    out.push_back(q);
  }
  return out;
}

Result<std::vector<Rigid3>> KdlChainPoses(const std::string& text, const std::string& name,
                                          const std::string& base_link, const std::string& tip_link,
                                          const std::vector<Eigen::VectorXd>& joints) {
  const Result<std::shared_ptr<::urdf::ModelInterface>> parsed = ParseUrdfText(text, name);
  if (!parsed.ok()) return parsed.status();
  Result<KDL::Chain> built = KdlChainOf(**parsed, name, base_link, tip_link);
  if (!built.ok()) return built.status();
  const KDL::Chain& chain = *built;
  KDL::ChainFkSolverPos_recursive solver(chain);
  std::vector<Rigid3> poses;
  for (const Eigen::VectorXd& q : joints) {
    if (q.size() != static_cast<int>(chain.getNrOfJoints())) {
      return Status::Error(ErrorCode::kInvalidInput, name + ": " + std::to_string(q.size()) +
                                                         " joint values for a chain of " +
                                                         std::to_string(chain.getNrOfJoints()) + " joints");
    }
    KDL::JntArray array(chain.getNrOfJoints());
    for (int j = 0; j < q.size(); ++j) array(j) = q[j];
    KDL::Frame frame;
    if (solver.JntToCart(array, frame) < 0) {
      return Status::Error(ErrorCode::kInternal, name + ": KDL's forward kinematics failed");
    }
    poses.push_back(RigidOf(frame));
  }
  return poses;
}

Result<UrdfRobot> ParseUrdfRobot(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                                 const std::optional<Rigid3>& flange_from_cam, const FkCheckOptions& options) {
  if (spec.base_link.empty() || spec.tip_link.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, name + ": a URDF robot needs base_link and tip_link");
  }
  if (spec.camera_link.empty() && !flange_from_cam) {
    return Status::Error(
        ErrorCode::kInvalidInput,
        name + ": give camera_link (a link of the URDF at the camera's optical frame) or flange_from_cam");
  }
  const Result<std::shared_ptr<::urdf::ModelInterface>> parsed = ParseUrdfText(text, name);
  if (!parsed.ok()) return parsed.status();
  Result<UrdfChain> chain = ExtractChain(**parsed, name, spec);
  if (!chain.ok()) return WithUrdfLine(text, name, chain.status());
  UrdfRobot robot;
  robot.model = ModelFromAxes(*chain, flange_from_cam.value_or(Rigid3()));
  for (const AxisLine& axis : chain->axes) robot.joint_names.push_back(axis.name);
  const std::string invalid = robot.model.Validate();
  if (!invalid.empty()) {
    return WithUrdfLine(text, name, Status::Error(ErrorCode::kInvalidInput, name + ": the converted model: " + invalid));
  }
  Result<FkCheck> check = CompareWithKdl(text, name, spec, robot.model, options);
  if (!check.ok()) return WithUrdfLine(text, name, check.status());
  robot.check = *check;
  return robot;
}

Result<UrdfRobot> LoadUrdfRobot(const std::string& path, const UrdfChainSpec& spec,
                                const std::optional<Rigid3>& flange_from_cam, const FkCheckOptions& options) {
  Result<std::string> text = ReadFileCapped(path, kMaxUrdfBytes);
  if (!text.ok()) return text.status();
  return ParseUrdfRobot(*text, path, spec, flange_from_cam, options);
}

}  // namespace selfcal::urdf
