// The packets of FANUC's Remote Motion Interface (RMI) that the FANUC backend speaks (fanuc_robot.h,
// docs/fanuc.md). Written from the packet definitions of FANUC's "Remote Motion Interface OPERATOR'S
// MANUAL" B-84184EN/03 as FANUC's Apache-2.0 reference client (fanuc_driver, rmi/packets.hpp) states them,
// section numbers below; nothing copied. Every packet is one JSON object on one line ending "\r\n":
//   - the connect port (16001): {"Communication":"FRC_Connect"} answered with ErrorID and PortNumber, the
//     port the session then uses (2.2.1); {"Communication":"FRC_Disconnect"} ends it (2.2.2);
//   - commands, answered at once (2.3): FRC_Initialize (2.3.1), FRC_Abort (2.3.2), FRC_GetStatus (2.3.7:
//     ServoReady, TPMode, RMIMotionStatus, ProgramStatus, NextSequenceID, ...), FRC_ReadJointAngles (2.3.15:
//     JointAngle J1..J9 in degrees), FRC_Reset (2.3.20);
//   - instructions, queued with a SequenceID and answered with it (2.4): FRC_JointMotionJRep (2.4.13), the
//     joint move to joint angles (FRC_JointMotion, 2.4.9, takes a Cartesian position instead);
//   - unsolicited: FRC_SystemFault (2.2.4, a fault while the instructions run) and FRC_Terminate (2.2.3).
// Joint angles are degrees on the wire and radians here.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "base/status.h"
#include "robot/robot.h"

namespace selfcal::robot::fanuc {

inline constexpr int kConnectPort = 16001;

// The three kinds of packet (the JSON key that names the packet).
enum class PacketKind { kCommunication, kCommand, kInstruction };

// {"Communication":"FRC_Connect"} and the like: a packet of `kind` named `name` with no other key, without
// the line end.
std::string SimpleRequest(PacketKind kind, const std::string& name);

// FRC_JointMotionJRep: the move to `target_rad` (6 joints, sent in degrees; J7..J9 0) at `speed_percent`
// (1-100, SpeedType "Percent") ending FINE, with `sequence_id`.
std::string JointMotionRequest(int sequence_id, const Eigen::VectorXd& target_rad, int speed_percent);

// FRC_GetStatus' answer (2.3.7).
struct ControllerStatus {
  int servo_ready = 0;        // 1: the servos are on and no alarm holds the arm
  int tp_mode = 0;            // 1: the teach pendant is enabled (RMI cannot move the arm)
  int rmi_motion_status = 0;  // 1: RMI's motion program is running
  int program_status = 0;
  int single_step = 0;
  int next_sequence_id = 0;
  int override_percent = 0;
};

// One packet received, whatever its kind: the fields the backend uses, the others ignored.
struct Packet {
  PacketKind kind = PacketKind::kCommand;
  std::string name;                 // "FRC_GetStatus", ..., "Unknown" (2.4.19)
  int error_id = 0;                 // ErrorID (0 when absent)
  std::optional<int> sequence_id;   // SequenceID
  std::optional<int> port;          // FRC_Connect's PortNumber
  int major_version = 0, minor_version = 0;  // FRC_Connect's
  std::optional<Eigen::VectorXd> joints_rad;  // FRC_ReadJointAngles' J1..J6
  std::optional<ControllerStatus> status;     // FRC_GetStatus'
};

// One received line as a packet (a request too: the answer fields are read and required only in a packet
// with ErrorID 0). kProtocol naming what is wrong (not JSON, not an object, no packet name,
// a field of the wrong type, FRC_ReadJointAngles without six finite joints, FRC_GetStatus without its
// fields); the controller's text in messages is escaped.
Result<Packet> ParsePacket(const std::string& line);

// The robot status a controller status means: kFault with the reason when the servos are not ready or the
// teach pendant is enabled, else kIdle.
RobotStatus StatusOf(const ControllerStatus& status);

// The fake's side (fanuc_fake.h): FRC_Connect's answer, a command's or instruction's answer with ErrorID
// (and SequenceID when given), FRC_ReadJointAngles' and FRC_GetStatus' answers, FRC_SystemFault.
std::string ConnectReply(int error_id, int port, int major_version, int minor_version);
std::string Reply(PacketKind kind, const std::string& name, int error_id, std::optional<int> sequence_id = std::nullopt);
std::string JointAnglesReply(const Eigen::VectorXd& q_rad, int time_tag);
std::string StatusReply(const ControllerStatus& status);
std::string SystemFault(int sequence_id);

// FRC_JointMotionJRep's target (radians) and speed; nullopt when `packet_text` is not one.
struct JointMotion {
  int sequence_id = 0;
  Eigen::VectorXd target_rad;
  int speed_percent = 0;
};
std::optional<JointMotion> ParseJointMotion(const std::string& packet_text);

}  // namespace selfcal::robot::fanuc
