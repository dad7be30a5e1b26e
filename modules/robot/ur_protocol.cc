#include "robot/ur_protocol.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>


namespace selfcal::robot::ur {
namespace {

// Big-endian writers and a bounds-checked reader.
void PutU8(std::string* out, uint8_t v) { out->push_back(static_cast<char>(v)); }
void PutU16(std::string* out, uint16_t v) {
  PutU8(out, static_cast<uint8_t>(v >> 8));
  PutU8(out, static_cast<uint8_t>(v));
}
void PutU32(std::string* out, uint32_t v) {
  PutU16(out, static_cast<uint16_t>(v >> 16));
  PutU16(out, static_cast<uint16_t>(v));
}
void PutF64(std::string* out, double v) {
  uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof(bits));
  PutU32(out, static_cast<uint32_t>(bits >> 32));
  PutU32(out, static_cast<uint32_t>(bits));
}

class Reader {
 public:
  explicit Reader(const std::string& bytes, size_t at = 0) : bytes_(bytes), at_(at) {}
  bool U8(uint8_t* v) {
    if (at_ + 1 > bytes_.size()) return false;
    *v = static_cast<uint8_t>(bytes_[at_++]);
    return true;
  }
  bool U32(uint32_t* v) {
    *v = 0;
    for (int k = 0; k < 4; ++k) {
      uint8_t b = 0;
      if (!U8(&b)) return false;
      *v = (*v << 8) | b;
    }
    return true;
  }
  bool F64(double* v) {
    uint32_t high = 0, low = 0;
    if (!U32(&high) || !U32(&low)) return false;
    const uint64_t bits = (static_cast<uint64_t>(high) << 32) | low;
    std::memcpy(v, &bits, sizeof(bits));
    return true;
  }
  size_t at() const { return at_; }
  size_t left() const { return bytes_.size() - at_; }

 private:
  const std::string& bytes_;
  size_t at_;
};

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
  return parts;
}

Status Protocol(const std::string& message) { return RobotFailure(RobotError::kProtocol, message); }

}  // namespace

const std::vector<std::string>& StateRecipeNames() {
  static const std::vector<std::string> names = {"actual_q", "actual_qd", "runtime_state", "safety_status_bits",
                                                 "robot_status_bits"};
  return names;
}

const std::vector<std::string>& StateRecipeTypes() {
  static const std::vector<std::string> types = {"VECTOR6D", "VECTOR6D", "UINT32", "UINT32", "UINT32"};
  return types;
}

std::string EncodeRtde(uint8_t type, const std::string& payload) {
  SELFCAL_CHECK(payload.size() + 3 <= 65535, "an RTDE package holds at most 65535 bytes");
  std::string out;
  PutU16(&out, static_cast<uint16_t>(payload.size() + 3));
  PutU8(&out, type);
  return out + payload;
}

Result<uint16_t> RtdePackageSize(const std::string& header) {
  SELFCAL_CHECK(header.size() >= 3, "an RTDE header is 3 bytes");
  const uint16_t size = static_cast<uint16_t>((static_cast<uint8_t>(header[0]) << 8) | static_cast<uint8_t>(header[1]));
  if (size < 3) return Protocol("RTDE package of size " + std::to_string(size) + ", below its 3-byte header");
  return size;
}

std::string ProtocolVersionRequest(uint16_t version) {
  std::string payload;
  PutU16(&payload, version);
  return EncodeRtde(kRtdeRequestProtocolVersion, payload);
}

std::string SetupOutputsRequest(double frequency_hz, const std::vector<std::string>& names) {
  std::string payload;
  PutF64(&payload, frequency_hz);
  for (size_t i = 0; i < names.size(); ++i) payload += (i ? "," : "") + names[i];
  return EncodeRtde(kRtdeSetupOutputs, payload);
}

Result<SetupOutputsReply> ParseSetupOutputsReply(const std::string& payload) {
  if (payload.empty()) return Protocol("RTDE output setup answer without a recipe id");
  SetupOutputsReply reply;
  reply.recipe_id = static_cast<uint8_t>(payload[0]);
  reply.types = SplitCommas(payload.substr(1));
  return reply;
}

Result<bool> ParseAccepted(const std::string& payload, const char* what) {
  if (payload.size() != 1) {
    return Protocol(std::string("RTDE ") + what + " answer of " + std::to_string(payload.size()) +
                    " bytes, not the 1-byte accepted flag");
  }
  return payload[0] != 0;
}

std::string EncodeStateData(uint8_t recipe_id, const UrState& state) {
  std::string out;
  PutU8(&out, recipe_id);
  for (int j = 0; j < 6; ++j) PutF64(&out, state.q_rad[j]);
  for (int j = 0; j < 6; ++j) PutF64(&out, state.qd_rad_s[j]);
  PutU32(&out, state.runtime_state);
  PutU32(&out, state.safety_status_bits);
  PutU32(&out, state.robot_status_bits);
  return out;
}

Result<UrState> DecodeStateData(const std::string& payload, uint8_t recipe_id) {
  constexpr size_t kSize = 1 + 12 * 8 + 3 * 4;
  if (payload.size() != kSize) {
    return Protocol("RTDE data package of " + std::to_string(payload.size()) + " bytes; the recipe needs " +
                    std::to_string(kSize));
  }
  Reader in(payload);
  uint8_t id = 0;
  in.U8(&id);
  if (id != recipe_id) {
    return Protocol("RTDE data package for recipe " + std::to_string(id) + ", not the recipe " +
                    std::to_string(recipe_id) + " set up");
  }
  UrState state;
  for (int j = 0; j < 6; ++j) in.F64(&state.q_rad[j]);
  for (int j = 0; j < 6; ++j) in.F64(&state.qd_rad_s[j]);
  in.U32(&state.runtime_state);
  in.U32(&state.safety_status_bits);
  in.U32(&state.robot_status_bits);
  return state;
}

RobotStatus StatusOfState(const UrState& state) {
  const uint32_t s = state.safety_status_bits;
  RobotStatus status;
  if (s & (kSafetySystemEmergencyStopped | kSafetyRobotEmergencyStopped | kSafetyEmergencyStopped)) {
    status.state = MotionState::kEmergencyStop;
    status.message = "emergency stop";
  } else if (s & (kSafetyProtectiveStopped | kSafetySafeguardStopped)) {
    status.state = MotionState::kProtectiveStop;
    status.message = (s & kSafetyProtectiveStopped) ? "protective stop" : "safeguard stop";
  } else if (s & (kSafetyViolation | kSafetyFault | kSafetyRecovery | kSafetyStoppedDueToSafety)) {
    status.state = MotionState::kFault;
    status.message = (s & kSafetyRecovery) ? "recovery mode" : "safety violation or fault";
  } else if (!(state.robot_status_bits & kRobotPowerOn)) {
    status.state = MotionState::kFault;
    status.message = "the arm is not powered on";
  }
  if (!status.message.empty()) {
    char bits[64];
    std::snprintf(bits, sizeof(bits), " (safety_status_bits 0x%x, robot_status_bits 0x%x)", s,
                  state.robot_status_bits);
    status.message += bits;
  }
  return status;
}

std::string EncodeRobotStateMessage(const KinematicsInfo& info) {
  std::string robot_mode;  // a placeholder sub-package a reader skips by its length
  PutU32(&robot_mode, 5 + 4);
  PutU8(&robot_mode, 0);
  PutU32(&robot_mode, 0);
  std::string kinematics;
  for (uint32_t c : info.checksum) PutU32(&kinematics, c);
  for (const auto* row : {&info.dh_theta, &info.dh_a, &info.dh_d, &info.dh_alpha}) {
    for (double v : *row) PutF64(&kinematics, v);
  }
  PutU32(&kinematics, info.calibration_status);
  std::string sub;
  PutU32(&sub, static_cast<uint32_t>(kinematics.size() + 5));
  PutU8(&sub, kKinematicsInfoPackage);
  const std::string body = robot_mode + sub + kinematics;
  std::string message;
  PutU32(&message, static_cast<uint32_t>(body.size() + 5));
  PutU8(&message, kPrimaryRobotState);
  return message + body;
}

Result<uint32_t> PrimaryMessageSize(const std::string& header) {
  SELFCAL_CHECK(header.size() >= 5, "a primary interface header is 5 bytes");
  uint32_t size = 0;
  Reader(header).U32(&size);
  if (size < 5 || size > (1u << 20)) {
    return Protocol("primary interface message of size " + std::to_string(size) + " bytes");
  }
  return size;
}

Result<std::optional<KinematicsInfo>> KinematicsInfoOf(const std::string& message) {
  if (message.size() < 5 || static_cast<uint8_t>(message[4]) != kPrimaryRobotState) {
    return std::optional<KinematicsInfo>();
  }
  size_t at = 5;
  while (at < message.size()) {
    Reader in(message, at);
    uint32_t size = 0;
    uint8_t type = 0;
    if (!in.U32(&size) || !in.U8(&type) || size < 5 || size > message.size() - at) {
      return Protocol("robot state sub-package at byte " + std::to_string(at) + " runs past its message");
    }
    if (type == kKinematicsInfoPackage) {
      KinematicsInfo info;
      if (size != 5 + 6 * 4 + 24 * 8 + 4) {
        return Protocol("kinematics info of " + std::to_string(size) + " bytes, not the 225 of six joints");
      }
      for (uint32_t& c : info.checksum) in.U32(&c);
      for (auto* row : {&info.dh_theta, &info.dh_a, &info.dh_d, &info.dh_alpha}) {
        for (double& v : *row) in.F64(&v);
      }
      in.U32(&info.calibration_status);
      return std::optional<KinematicsInfo>(info);
    }
    at += size;
  }
  return std::optional<KinematicsInfo>();
}

std::string CalibrationIdOf(const KinematicsInfo& info) {
  std::string id = "ur-kinematics";
  for (uint32_t c : info.checksum) {
    char hex[16];
    std::snprintf(hex, sizeof(hex), "-%08x", c);
    id += hex;
  }
  return id;
}

std::string MovejScript(const Eigen::VectorXd& q_rad, double acceleration_rad_s2, double velocity_rad_s) {
  std::string line = "movej([";
  char number[40];
  for (Eigen::Index j = 0; j < q_rad.size(); ++j) {
    std::snprintf(number, sizeof(number), "%s%.10f", j ? ", " : "", q_rad[j]);
    line += number;
  }
  std::snprintf(number, sizeof(number), "], a=%.6f", acceleration_rad_s2);
  line += number;
  std::snprintf(number, sizeof(number), ", v=%.6f)", velocity_rad_s);
  return line + number;
}

std::string StopjScript(double deceleration_rad_s2) {
  char line[40];
  std::snprintf(line, sizeof(line), "stopj(%.6f)", deceleration_rad_s2);
  return line;
}

std::optional<Eigen::VectorXd> ParseMovej(const std::string& line, double* velocity_rad_s) {
  double q[6], a = 0, v = 0;
  char end = 0;
  const int read = std::sscanf(line.c_str(), "movej([%lf, %lf, %lf, %lf, %lf, %lf], a=%lf, v=%lf%c", &q[0], &q[1],
                               &q[2], &q[3], &q[4], &q[5], &a, &v, &end);
  if (read != 9 || end != ')' || !(v > 0) || !(a > 0) || !std::isfinite(v) || !std::isfinite(a)) return std::nullopt;
  for (double qj : q) {
    if (!std::isfinite(qj)) return std::nullopt;
  }
  if (velocity_rad_s != nullptr) *velocity_rad_s = v;
  return Eigen::Map<const Eigen::VectorXd>(q, 6).eval();
}

std::string DashboardValue(const std::string& reply, const std::string& prefix) {
  if (reply.rfind(prefix, 0) != 0) return "";
  std::string value = reply.substr(prefix.size());
  while (!value.empty() && value.front() == ' ') value.erase(0, 1);
  return value;
}

}  // namespace selfcal::robot::ur
