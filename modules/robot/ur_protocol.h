// The byte formats of a Universal Robots controller that the UR backend (ur_robot.h) and its loopback fake
// (ur_fake.h) speak, written from UR's published documents (docs/universal-robots.md says which part was
// checked against which document):
//   - RTDE (port 30004), "Real-Time Data Exchange (RTDE) Guide": every package is a 3-byte header (uint16
//     size of the whole package, header included; uint8 type) and a payload, all big-endian. The client
//     asks for protocol version 2 ('V'), sets up an output recipe ('O': double frequency, then the
//     comma-separated variable names; the answer: uint8 recipe id, then the comma-separated types, or
//     NOT_FOUND per unknown name), starts ('S', answered by uint8 accepted) and then receives data packages
//     ('U': uint8 recipe id, then the variables in recipe order).
//   - The primary/secondary client interface (ports 30001/30002), "Client Interface" reference: messages
//     of int32 length (header included) and uint8 type; a robot state message (type 16) is a sequence of
//     sub-packages of int32 length and uint8 type, the kinematics info (type 5) holding six uint32
//     checksums, the DH theta, a, d and alpha of the six joints (doubles: the factory calibration) and a
//     uint32 calibration status. URScript text sent to that port runs as a program ("The URScript
//     Programming Language": movej, stopj).
//   - The Dashboard server (port 29999), "Dashboard Server" reference: text lines, a greeting on connect.
// Pure functions on bytes and text: no sockets here.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "robot/robot.h"

namespace selfcal::robot::ur {

inline constexpr int kRtdePort = 30004;
inline constexpr int kSecondaryPort = 30002;
inline constexpr int kDashboardPort = 29999;
inline constexpr uint16_t kRtdeProtocolVersion = 2;

enum RtdeType : uint8_t {
  kRtdeRequestProtocolVersion = 86,  // 'V'
  kRtdeTextMessage = 77,             // 'M'
  kRtdeDataPackage = 85,             // 'U'
  kRtdeSetupOutputs = 79,            // 'O'
  kRtdeStart = 83,                   // 'S'
  kRtdePause = 80,                   // 'P'
};

// The output recipe the backend asks for, in this order, and the types the guide lists for them.
const std::vector<std::string>& StateRecipeNames();
const std::vector<std::string>& StateRecipeTypes();

// One RTDE package: its type and payload (the header removed).
struct RtdePackage {
  uint8_t type = 0;
  std::string payload;
};

// Header + payload. Throws InvalidArgument when the package would exceed 65535 bytes (a caller error).
std::string EncodeRtde(uint8_t type, const std::string& payload);
// The size field of a header (the first 3 bytes of `header`); kProtocol when below 3.
Result<uint16_t> RtdePackageSize(const std::string& header);

std::string ProtocolVersionRequest(uint16_t version);
std::string SetupOutputsRequest(double frequency_hz, const std::vector<std::string>& names);
// The payloads of the controller's answers.
struct SetupOutputsReply {
  uint8_t recipe_id = 0;
  std::vector<std::string> types;
};
Result<SetupOutputsReply> ParseSetupOutputsReply(const std::string& payload);
// Whether a one-byte "accepted" answer says yes; kProtocol when it is not one byte.
Result<bool> ParseAccepted(const std::string& payload, const char* what);

// Bits of robot_status_bits and safety_status_bits (RTDE guide, output table).
inline constexpr uint32_t kRobotPowerOn = 1u << 0;
inline constexpr uint32_t kSafetyNormal = 1u << 0;
inline constexpr uint32_t kSafetyProtectiveStopped = 1u << 2;
inline constexpr uint32_t kSafetyRecovery = 1u << 3;
inline constexpr uint32_t kSafetySafeguardStopped = 1u << 4;
inline constexpr uint32_t kSafetySystemEmergencyStopped = 1u << 5;
inline constexpr uint32_t kSafetyRobotEmergencyStopped = 1u << 6;
inline constexpr uint32_t kSafetyEmergencyStopped = 1u << 7;
inline constexpr uint32_t kSafetyViolation = 1u << 8;
inline constexpr uint32_t kSafetyFault = 1u << 9;
inline constexpr uint32_t kSafetyStoppedDueToSafety = 1u << 10;

// One data package of the state recipe.
struct UrState {
  Eigen::Matrix<double, 6, 1> q_rad = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> qd_rad_s = Eigen::Matrix<double, 6, 1>::Zero();
  uint32_t runtime_state = 1;  // 1 stopped, 2 playing (RTDE guide)
  uint32_t safety_status_bits = kSafetyNormal;
  uint32_t robot_status_bits = kRobotPowerOn;
};
std::string EncodeStateData(uint8_t recipe_id, const UrState& state);  // the payload of a 'U' package
Result<UrState> DecodeStateData(const std::string& payload, uint8_t recipe_id);

// The motion state the safety and robot status bits describe (moving or not is the backend's to say):
// kProtectiveStop for a protective or safeguard stop, kEmergencyStop for any emergency stop, kFault for a
// violation, a fault, recovery mode or the arm powered off; otherwise kIdle. `message` names the bits.
RobotStatus StatusOfState(const UrState& state);

// The kinematics info sub-package of the primary interface's robot state message.
struct KinematicsInfo {
  std::array<uint32_t, 6> checksum{};
  std::array<double, 6> dh_theta{}, dh_a{}, dh_d{}, dh_alpha{};
  uint32_t calibration_status = 0;
};
inline constexpr uint8_t kPrimaryRobotState = 16;
inline constexpr uint8_t kKinematicsInfoPackage = 5;
// A robot state message holding a robot mode sub-package placeholder (type 0, skipped by readers) and the
// kinematics info: what the fake sends.
std::string EncodeRobotStateMessage(const KinematicsInfo& info);
// The int32 length of a primary message header (its first 5 bytes); kProtocol when below 5 or absurd.
Result<uint32_t> PrimaryMessageSize(const std::string& header);
// The kinematics info of one whole primary message, nullopt when it is another message or has none;
// kProtocol for a sub-package whose length runs past the message.
Result<std::optional<KinematicsInfo>> KinematicsInfoOf(const std::string& message);
// "ur-kinematics-<6 checksums as 8 hex digits, joined by '-'>": the calibration id the session records.
std::string CalibrationIdOf(const KinematicsInfo& info);

// URScript lines (no newline): movej([q1, ..., q6], a=..., v=...) and stopj(a). Radians, rad/s, rad/s^2.
std::string MovejScript(const Eigen::VectorXd& q_rad, double acceleration_rad_s2, double velocity_rad_s);
std::string StopjScript(double deceleration_rad_s2);
// The joints of a movej line as MovejScript writes it; nullopt for anything else.
std::optional<Eigen::VectorXd> ParseMovej(const std::string& line, double* velocity_rad_s);

// The text after "Safetystatus: " / "Robotmode: " ("" when the prefix is missing).
std::string DashboardValue(const std::string& reply, const std::string& prefix);

}  // namespace selfcal::robot::ur
