#include "app/model_exports.h"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/cli_output.h"
#include "base/atomic_file.h"
#include "io/dh_config_file.h"
#include "io/static_transform_file.h"
#include "io/ur_kinematics_file.h"
#include "kinematics/dh_table.h"
#include "base/terminal_text.h"
#include "urdf/urdf_calibrated.h"
#include "urdf/urdf_writer.h"

namespace selfcal::app {
namespace {

// calibrated_robot.yaml when the entered convention holds the model exactly; otherwise why not.
Status WriteDhTable(const RobotModel& calibrated, const std::string& convention, const std::string& source,
                    const std::filesystem::path& out) {
  if (convention.empty()) return Status::Ok();  // entered as a URDF: calibrated.urdf is its export
  const DhExpression dh = ExpressAsDh(calibrated, convention);
  nlohmann::json doc = {{"convention", convention}, {"written", dh.exact}};
  if (dh.exact) {
    const std::string path = (out / "calibrated_robot.yaml").string();
    if (Status s = io::SaveDhRobotConfig(dh.table, calibrated.name, source, path); !s.ok()) return s;
    std::cout << "calibrated robot (" << convention << " DH, the robot config's convention): " << path << "\n";
    AddOutputFile("calibrated_robot", path);
  } else {
    std::ostringstream why;
    why << "calibrated robot (" << convention << " DH): not written, the calibrated model is not expressible in it:";
    for (const std::string& loss : dh.losses) why << "\n  " << loss;
    if (dh.dropped_position_m > 0 || dh.dropped_rotation_rad > 0) {
      why << "\n  dropping them would move the flange by up to " << std::setprecision(3) << dh.dropped_position_m * 1e3
          << " mm / " << RadToDeg(dh.dropped_rotation_rad) << " deg (200 random joints within the limits)";
    }
    why << "\n  calibrated_model.yaml (modified DH + Hayati) and calibrated.urdf hold it exactly";
    std::cout << why.str() << "\n";
    doc["losses"] = dh.losses;
    doc["dropped_flange_position_mm"] = dh.dropped_position_m * 1e3;
    doc["dropped_flange_rotation_deg"] = RadToDeg(dh.dropped_rotation_rad);
  }
  OutputDocument()["dh_table"] = doc;
  return Status::Ok();
}

// ur_calibrated_kinematics.yaml for a Universal Robots arm (io/ur_kinematics_file.h), or why not.
// The file's chain starts at ur_description's base_link_inertia (the controller's Base frame): the model's
// base for a DH config, and for a URDF robot only when its base_link is that link (ur_description's own
// base_link is turned 180 deg about z from it).
Status WriteUrKinematics(const RobotModel& calibrated, const io::RobotOrigin& origin, const std::filesystem::path& out) {
  if (!io::IsUniversalRobotsArm(calibrated)) return Status::Ok();
  const std::string path = (out / "ur_calibrated_kinematics.yaml").string();
  Result<std::string> text =
      origin.FromUrdf() && origin.base_link != "base_link_inertia"
          ? Result<std::string>(Status::Error(ErrorCode::kInvalidInput,
                                              "the model's base is the URDF's `" + origin.base_link +
                                                  "`, not ur_description's base_link_inertia, where the file's chain starts"))
          : io::UrKinematicsYaml(calibrated);
  if (!text.ok()) {
    std::cout << "ur_description kinematics: not written, " << text.status().message() << "\n";
    return Status::Ok();
  }
  if (Status s = WriteFileAtomically(path, *text); !s.ok()) return s;
  std::cout << "ur_description kinematics (kinematics_params_file): " << path << "\n";
  AddOutputFile("ur_kinematics", path);
  return Status::Ok();
}

// The URDF's names when the robot came from one (and the joint count agrees), else the writer's defaults.
urdf::UrdfNames NamesOf(const io::RobotOrigin& origin, int num_joints) {
  urdf::UrdfNames names;
  const auto joints_of = [num_joints](const auto& values) { return static_cast<int>(values.size()) == num_joints; };
  if (joints_of(origin.max_velocity_rad_s)) names.velocities_rad_s = origin.max_velocity_rad_s;
  if (!origin.FromUrdf()) {  // a DH config's own names, when it gives them
    if (joints_of(origin.config_joint_names)) names.joints = origin.config_joint_names;
    if (joints_of(origin.config_link_names)) names.links = origin.config_link_names;
    return names;
  }
  if (!joints_of(origin.joint_names)) return names;
  names.joints = origin.joint_names;
  if (!origin.base_link.empty()) names.base_link = origin.base_link;
  if (!origin.tip_link.empty()) names.tip_link = origin.tip_link;
  if (!origin.camera_link.empty()) names.camera_link = origin.camera_link;
  return names;
}

// calibrated.urdf: the user's URDF with the calibrated joint origins when the robot came from a URDF file
// that is still there and converts to this model (urdf/urdf_calibrated.h), else selfcal's own URDF of the
// model with the input's names (urdf/urdf_writer.h).
Status WriteCalibratedUrdf(const RobotModel& calibrated, const io::RobotOrigin& origin, const std::string& path) {
  if (!origin.urdf_file.empty()) {
    Result<std::string> text = urdf::CalibratedUserUrdfFile(
        origin.urdf_file, {origin.base_link, origin.tip_link, origin.camera_link}, calibrated);
    if (text.ok()) {
      if (Status s = WriteFileAtomically(path, *text); !s.ok()) return s;
      std::cout << "calibrated URDF (" << origin.urdf_file << " with the calibrated joint origins): " << path << "\n";
      return Status::Ok();
    }
    std::cout << "calibrated URDF: " << origin.urdf_file << " cannot take the calibrated origins ("
              << TerminalSafe(text.status().message()) << "); selfcal's URDF of the model with its names instead\n";
  }
  if (Status s = urdf::WriteUrdf(calibrated, NamesOf(origin, calibrated.num_joints()), path); !s.ok()) return s;
  std::cout << "calibrated URDF: " << path << "\n";
  return Status::Ok();
}

}  // namespace

io::RobotOrigin OriginOfInput(const std::string& robot_config, const std::string& input, bool is_session) {
  Result<io::RobotOrigin> origin =
      !robot_config.empty() ? io::RobotOriginOfConfig(robot_config)
      : is_session          ? io::RobotOriginOfConfig((std::filesystem::path(input) / "inputs" / "robot.yaml").string())
                            : io::RobotOriginOfObservations(input);
  return origin.ok() ? *origin : io::RobotOrigin{};
}

Status WriteModelExports(const RobotModel& calibrated, const io::RobotOrigin& origin, const std::string& source,
                         const std::string& out_dir) {
  const std::filesystem::path out(out_dir);
  const std::string urdf_path = (out / "calibrated.urdf").string();  // docs/urdf.md
  if (Status s = WriteCalibratedUrdf(calibrated, origin, urdf_path); !s.ok()) return s;
  AddOutputFile("calibrated_urdf", urdf_path);
  if (Status s = WriteDhTable(calibrated, origin.dh_convention, source, out); !s.ok()) return s;
  if (Status s = WriteUrKinematics(calibrated, origin, out); !s.ok()) return s;
  const bool eye_to_hand = calibrated.mount == CameraMount::kEyeToHand;
  return WriteCameraStaticTransform(calibrated.mount, eye_to_hand ? calibrated.base_from_cam : calibrated.flange_from_cam,
                                    origin, out_dir);
}

Status WriteCameraStaticTransform(CameraMount mount, const Rigid3& parent_from_cam, const io::RobotOrigin& origin,
                                  const std::string& out_dir) {
  const urdf::UrdfNames names = NamesOf(origin, static_cast<int>(origin.joint_names.size()));
  const bool eye_to_hand = mount == CameraMount::kEyeToHand;
  const std::string& parent = eye_to_hand ? names.base_link : names.tip_link;
  const io::StaticTransform transform{parent, names.camera_link, parent_from_cam};
  const std::string path = (std::filesystem::path(out_dir) / "camera_static_transform.yaml").string();
  if (Status s = io::SaveStaticTransform(transform, path); !s.ok()) return s;
  std::cout << (eye_to_hand ? "base-to-camera" : "flange-to-camera") << " static transform (" << parent << " -> "
            << names.camera_link << "): " << path << "\n";
  AddOutputFile("camera_static_transform", path);
  const std::string launch_path = (std::filesystem::path(out_dir) / "camera_static_transform.launch.py").string();
  if (Status s = io::SaveStaticTransformLaunch(transform, launch_path); !s.ok()) return s;
  std::cout << "the same as a ROS 2 launch file: " << launch_path << "\n";
  AddOutputFile("camera_static_transform_launch", launch_path);
  return Status::Ok();
}

}  // namespace selfcal::app
