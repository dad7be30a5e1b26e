#include "robot/fanuc_protocol.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "base/terminal_text.h"

namespace selfcal::robot::fanuc {
namespace {

using nlohmann::json;

constexpr double kDegPerRad = 57.29577951308232;
constexpr const char* kJointKeys[] = {"J1", "J2", "J3", "J4", "J5", "J6", "J7", "J8", "J9"};

const char* KeyOf(PacketKind kind) {
  switch (kind) {
    case PacketKind::kCommunication: return "Communication";
    case PacketKind::kInstruction: return "Instruction";
    case PacketKind::kCommand: break;
  }
  return "Command";
}

Status Bad(const std::string& what, const std::string& line) {
  std::string shown = line.size() > 200 ? line.substr(0, 200) + "..." : line;
  return RobotFailure(RobotError::kProtocol, "RMI: " + what + " in \"" + TerminalSafe(shown) + "\"");
}

// An integer field: absent -> fallback; present and not an integer -> nullopt.
std::optional<int> IntField(const json& packet, const char* key, int fallback) {
  const auto it = packet.find(key);
  if (it == packet.end()) return fallback;
  if (!it->is_number_integer() && !it->is_number_unsigned()) return std::nullopt;
  const auto value = it->get<int64_t>();
  if (value < INT32_MIN || value > INT32_MAX) return std::nullopt;
  return static_cast<int>(value);
}

Status ReadStatusFields(const json& packet, const std::string& line, ControllerStatus* status) {
  const std::pair<const char*, int*> fields[] = {
      {"ServoReady", &status->servo_ready},       {"TPMode", &status->tp_mode},
      {"RMIMotionStatus", &status->rmi_motion_status}, {"ProgramStatus", &status->program_status},
      {"SingleStepMode", &status->single_step},   {"NextSequenceID", &status->next_sequence_id},
      {"Override", &status->override_percent}};
  for (const auto& [key, out] : fields) {
    if (!packet.contains(key)) return Bad(std::string("FRC_GetStatus without ") + key, line);
    const std::optional<int> value = IntField(packet, key, 0);
    if (!value) return Bad(std::string("FRC_GetStatus' ") + key + " is not an integer", line);
    *out = *value;
  }
  return Status::Ok();
}

Status ReadJointFields(const json& packet, const std::string& line, Eigen::VectorXd* joints_rad) {
  const auto angles = packet.find("JointAngle");
  if (angles == packet.end() || !angles->is_object()) return Bad("FRC_ReadJointAngles without JointAngle", line);
  joints_rad->resize(6);
  for (int j = 0; j < 6; ++j) {
    const auto it = angles->find(kJointKeys[j]);
    if (it == angles->end() || !it->is_number() || !std::isfinite(it->get<double>())) {
      return Bad(std::string("FRC_ReadJointAngles without a finite ") + kJointKeys[j], line);
    }
    (*joints_rad)[j] = it->get<double>() / kDegPerRad;
  }
  return Status::Ok();
}

}  // namespace

std::string SimpleRequest(PacketKind kind, const std::string& name) { return json{{KeyOf(kind), name}}.dump(); }

std::string JointMotionRequest(int sequence_id, const Eigen::VectorXd& target_rad, int speed_percent) {
  json angles = json::object();
  for (int j = 0; j < 9; ++j) angles[kJointKeys[j]] = j < target_rad.size() ? target_rad[j] * kDegPerRad : 0.0;
  return json{{"Instruction", "FRC_JointMotionJRep"}, {"SequenceID", sequence_id}, {"JointAngle", angles},
              {"SpeedType", "Percent"}, {"Speed", speed_percent}, {"TermType", "FINE"}, {"TermValue", 0}}
      .dump();
}

Result<Packet> ParsePacket(const std::string& line) {
  const json packet = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (packet.is_discarded() || !packet.is_object()) return Bad("not a JSON object", line);
  Packet out;
  int named = 0;
  for (PacketKind kind : {PacketKind::kCommunication, PacketKind::kCommand, PacketKind::kInstruction}) {
    const auto it = packet.find(KeyOf(kind));
    if (it == packet.end()) continue;
    if (!it->is_string()) return Bad(std::string(KeyOf(kind)) + " is not a string", line);
    out.kind = kind;
    out.name = it->get<std::string>();
    ++named;
  }
  if (named != 1) return Bad("not one of Communication, Command, Instruction", line);
  const std::optional<int> error_id = IntField(packet, "ErrorID", 0);
  if (!error_id) return Bad("ErrorID is not an integer", line);
  out.error_id = *error_id;
  if (packet.contains("SequenceID")) {
    const std::optional<int> sequence = IntField(packet, "SequenceID", 0);
    if (!sequence) return Bad("SequenceID is not an integer", line);
    out.sequence_id = *sequence;
  }
  const bool answered = packet.contains("ErrorID") && out.error_id == 0;  // an answer's fields; a request has none
  if (out.name == "FRC_Connect" && answered) {
    const std::optional<int> port = IntField(packet, "PortNumber", -1);
    if (!port || *port < 1 || *port > 65535) return Bad("FRC_Connect without a PortNumber in 1-65535", line);
    out.port = *port;
    out.major_version = IntField(packet, "MajorVersion", 0).value_or(0);
    out.minor_version = IntField(packet, "MinorVersion", 0).value_or(0);
  } else if (out.name == "FRC_ReadJointAngles" && answered) {
    Eigen::VectorXd joints;
    if (Status s = ReadJointFields(packet, line, &joints); !s.ok()) return s;
    out.joints_rad = joints;
  } else if (out.name == "FRC_GetStatus" && answered) {
    ControllerStatus status;
    if (Status s = ReadStatusFields(packet, line, &status); !s.ok()) return s;
    out.status = status;
  }
  return out;
}

RobotStatus StatusOf(const ControllerStatus& status) {
  RobotStatus out;
  if (status.tp_mode != 0) {
    out.state = MotionState::kFault;
    out.message = "the teach pendant is enabled (FRC_GetStatus TPMode 1): RMI cannot move the arm";
  } else if (status.servo_ready != 1) {
    out.state = MotionState::kFault;
    out.message = "the servos are not ready (FRC_GetStatus ServoReady " + std::to_string(status.servo_ready) +
                  "): an alarm, a stop or the servo power holds the arm";
  }
  return out;
}

std::string ConnectReply(int error_id, int port, int major_version, int minor_version) {
  return json{{"Communication", "FRC_Connect"}, {"ErrorID", error_id}, {"PortNumber", port},
              {"MajorVersion", major_version}, {"MinorVersion", minor_version}}
      .dump();
}

std::string Reply(PacketKind kind, const std::string& name, int error_id, std::optional<int> sequence_id) {
  json packet{{KeyOf(kind), name}, {"ErrorID", error_id}};
  if (sequence_id) packet["SequenceID"] = *sequence_id;
  return packet.dump();
}

std::string JointAnglesReply(const Eigen::VectorXd& q_rad, int time_tag) {
  json angles = json::object();
  for (int j = 0; j < 9; ++j) angles[kJointKeys[j]] = j < q_rad.size() ? q_rad[j] * kDegPerRad : 0.0;
  return json{{"Command", "FRC_ReadJointAngles"}, {"ErrorID", 0}, {"TimeTag", time_tag}, {"JointAngle", angles}}.dump();
}

std::string StatusReply(const ControllerStatus& s) {
  return json{{"Command", "FRC_GetStatus"}, {"ErrorID", 0}, {"ServoReady", s.servo_ready}, {"TPMode", s.tp_mode},
              {"RMIMotionStatus", s.rmi_motion_status}, {"ProgramStatus", s.program_status},
              {"SingleStepMode", s.single_step}, {"NumberUTool", 1}, {"NextSequenceID", s.next_sequence_id},
              {"NumberUFrame", 0}, {"Override", s.override_percent}}
      .dump();
}

std::string SystemFault(int sequence_id) {
  return json{{"Communication", "FRC_SystemFault"}, {"SequenceID", sequence_id}}.dump();
}

std::optional<JointMotion> ParseJointMotion(const std::string& packet_text) {
  const json packet = json::parse(packet_text, nullptr, false);
  if (packet.is_discarded() || !packet.is_object() || packet.value("Instruction", json()) != "FRC_JointMotionJRep") {
    return std::nullopt;
  }
  const auto angles = packet.find("JointAngle");
  const std::optional<int> sequence = IntField(packet, "SequenceID", -1);
  const std::optional<int> speed = IntField(packet, "Speed", -1);
  if (angles == packet.end() || !angles->is_object() || !sequence || !speed) return std::nullopt;
  JointMotion motion;
  motion.sequence_id = *sequence;
  motion.speed_percent = *speed;
  motion.target_rad.resize(6);
  for (int j = 0; j < 6; ++j) {
    const auto it = angles->find(kJointKeys[j]);
    if (it == angles->end() || !it->is_number() || !std::isfinite(it->get<double>())) return std::nullopt;
    motion.target_rad[j] = it->get<double>() / kDegPerRad;
  }
  return motion;
}

}  // namespace selfcal::robot::fanuc
