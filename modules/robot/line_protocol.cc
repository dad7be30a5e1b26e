#include "robot/line_protocol.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

namespace selfcal::robot::protocol {
namespace {

constexpr size_t kQuotedLineBytes = 200;  // how much of a bad line a message quotes

std::string Quote(std::string_view line) {
  std::string quoted = "\"" + std::string(line.substr(0, kQuotedLineBytes));
  if (line.size() > kQuotedLineBytes) quoted += "...";
  return quoted + "\"";
}

Status Malformed(const std::string& who, RequestKind request, std::string_view line, const std::string& why) {
  return RobotFailure(RobotError::kProtocol, who + ": " + RequestWord(request) + ": malformed reply " + Quote(line) +
                                                 ": " + why);
}

// Free text on a line: line breaks become spaces.
std::string OneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

// What follows `token` (a view into `line`) on the line, without the spaces after it: free text.
std::string_view RestAfter(std::string_view line, std::string_view token) {
  std::string_view rest = line.substr(static_cast<size_t>(token.data() - line.data()) + token.size());
  while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
  return rest;
}

RobotError ErrorOfCode(std::string_view code, RobotError fault_error) {
  if (code == kErrRejected) return RobotError::kRejected;
  if (code == kErrProtectiveStop) return RobotError::kProtectiveStop;
  if (code == kErrEmergencyStop) return RobotError::kEmergencyStop;
  if (code == kErrFault) return fault_error;
  return RobotError::kProtocol;  // bad_request, or a code this client does not know
}

// The tokens after "OK", or the failure an ERR reply (or a malformed line) stands for.
Result<std::vector<std::string_view>> OkTokens(std::string_view line, RequestKind request, RobotError fault_error,
                                               const std::string& who) {
  std::vector<std::string_view> tokens = SplitTokens(line);
  if (!tokens.empty() && tokens[0] == "OK") {
    tokens.erase(tokens.begin());
    return tokens;
  }
  if (tokens.size() >= 2 && tokens[0] == "ERR") {
    const std::string_view text = RestAfter(line, tokens[1]);
    return RobotFailure(ErrorOfCode(tokens[1], fault_error), who + ": " + RequestWord(request) + ": controller error " +
                                                                 std::string(tokens[1]) + ": " + std::string(text));
  }
  return Malformed(who, request, line, "expected OK or ERR <code>");
}

// All of `tokens` as numbers, or the first one that is not.
bool ParseNumbers(const std::vector<std::string_view>& tokens, size_t first, Eigen::VectorXd* values,
                  std::string* bad_token) {
  values->resize(static_cast<Eigen::Index>(tokens.size() - first));
  for (size_t i = first; i < tokens.size(); ++i) {
    if (!ParseNumber(tokens[i], &(*values)[static_cast<Eigen::Index>(i - first)])) {
      *bad_token = std::string(tokens[i]);
      return false;
    }
  }
  return true;
}

void AppendNumbers(const Eigen::VectorXd& values, std::string* line) {
  for (Eigen::Index i = 0; i < values.size(); ++i) *line += " " + FormatNumber(values[i]);
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string FormatNumber(double value) {
  char buffer[64];
  const std::to_chars_result written =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 17);
  return std::string(buffer, written.ptr);
}

bool ParseNumber(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const std::from_chars_result parsed = std::from_chars(token.data(), end, *value, std::chars_format::general);
  return parsed.ec == std::errc() && parsed.ptr == end;
}

std::string PercentEncode(std::string_view text) {
  std::string encoded;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < '!' || byte > '~' || c == '%' || c == '=') {
      char escape[4];
      std::snprintf(escape, sizeof(escape), "%%%02X", byte);
      encoded += escape;
    } else {
      encoded += c;
    }
  }
  return encoded;
}

bool PercentDecode(std::string_view token, std::string* text) {
  text->clear();
  for (size_t i = 0; i < token.size(); ++i) {
    if (token[i] != '%') {
      *text += token[i];
      continue;
    }
    if (i + 2 >= token.size()) return false;
    const int high = HexValue(token[i + 1]), low = HexValue(token[i + 2]);
    if (high < 0 || low < 0) return false;
    *text += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return true;
}

std::vector<std::string_view> SplitTokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t at = 0;
  while (at < line.size()) {
    if (line[at] == ' ') {
      ++at;
      continue;
    }
    const size_t end = std::min(line.find(' ', at), line.size());
    tokens.push_back(line.substr(at, end - at));
    at = end;
  }
  return tokens;
}

const char* RequestWord(RequestKind kind) {
  switch (kind) {
    case RequestKind::kHello:
      return "HELLO";
    case RequestKind::kLimits:
      return "LIMITS";
    case RequestKind::kJoints:
      return "JOINTS";
    case RequestKind::kMove:
      return "MOVE";
    case RequestKind::kStatus:
      return "STATUS";
    case RequestKind::kStop:
      return "STOP";
    case RequestKind::kBye:
      return "BYE";
  }
  return "?";
}

std::string HelloRequest() { return std::string("HELLO ") + kName + " " + std::to_string(kVersion); }

std::string MoveRequest(const Eigen::VectorXd& target_rad, double velocity_scaling) {
  std::string line = "MOVE " + FormatNumber(velocity_scaling);
  AppendNumbers(target_rad, &line);
  return line;
}

Result<Request> ParseRequest(std::string_view line) {
  const std::vector<std::string_view> tokens = SplitTokens(line);
  if (tokens.empty()) return Status::Error(ErrorCode::kInvalidInput, "empty request");
  Request request;
  bool known = false;
  for (const RequestKind kind : {RequestKind::kHello, RequestKind::kLimits, RequestKind::kJoints, RequestKind::kMove,
                                 RequestKind::kStatus, RequestKind::kStop, RequestKind::kBye}) {
    if (tokens[0] == RequestWord(kind)) {
      request.kind = kind;
      known = true;
    }
  }
  const std::string word(tokens[0].substr(0, 40));
  if (!known) return Status::Error(ErrorCode::kInvalidInput, "unknown request \"" + word + "\"");
  if (request.kind == RequestKind::kHello) {
    if (tokens.size() != 3 || tokens[1] != kName || tokens[2] != std::to_string(kVersion)) {
      return Status::Error(ErrorCode::kInvalidInput, std::string("unsupported protocol: this server speaks \"") +
                                                 HelloRequest() + "\"");
    }
    return request;
  }
  if (request.kind == RequestKind::kMove) {
    std::string bad;
    Eigen::VectorXd values;
    if (tokens.size() < 3) return Status::Error(ErrorCode::kInvalidInput, "MOVE needs a scaling and the joint targets");
    if (!ParseNumbers(tokens, 1, &values, &bad)) {
      return Status::Error(ErrorCode::kInvalidInput, "MOVE: \"" + bad.substr(0, 40) + "\" is not a number");
    }
    request.velocity_scaling = values[0];
    request.target_rad = values.tail(values.size() - 1);
    return request;
  }
  if (tokens.size() != 1) return Status::Error(ErrorCode::kInvalidInput, word + " takes no arguments");
  return request;
}

const char* ErrorCodeFor(RobotError error) {
  switch (error) {
    case RobotError::kRejected:
      return kErrRejected;
    case RobotError::kProtectiveStop:
      return kErrProtectiveStop;
    case RobotError::kEmergencyStop:
      return kErrEmergencyStop;
    default:
      return kErrFault;
  }
}

std::string OkReply() { return "OK"; }

std::string ErrorReply(std::string_view code, std::string_view text) {
  return OneLine("ERR " + std::string(code) + " " + std::string(text));
}

std::string HelloReply(const RobotIdentity& identity, int num_joints) {
  return std::string("OK ") + kName + " " + std::to_string(kVersion) + " model=" + PercentEncode(identity.model) +
         " serial=" + PercentEncode(identity.serial) + " calibration=" + PercentEncode(identity.calibration_id) +
         " joints=" + std::to_string(num_joints) + " real=" + (identity.real_hardware ? "1" : "0");
}

std::string LimitsReply(const JointLimits& limits) {
  std::string line = "OK";
  AppendNumbers(limits.lower_rad, &line);
  AppendNumbers(limits.upper_rad, &line);
  AppendNumbers(limits.max_velocity_rad_s, &line);
  return line;
}

std::string JointsReply(const JointReading& reading) {
  std::string line = "OK " + FormatNumber(reading.time_s);
  AppendNumbers(reading.position_rad, &line);
  AppendNumbers(reading.velocity_rad_s, &line);
  return line;
}

std::string StatusReply(const RobotStatus& status) {
  std::string line = std::string("OK ") + MotionStateName(status.state);
  if (!status.message.empty()) line += " " + status.message;
  return OneLine(line);
}

Result<HelloInfo> ParseHelloReply(std::string_view line, const std::string& who) {
  const Result<std::vector<std::string_view>> tokens = OkTokens(line, RequestKind::kHello, RobotError::kNotConnected, who);
  if (!tokens.ok()) return tokens.status();
  if (tokens->size() < 2 || (*tokens)[0] != kName || (*tokens)[1] != std::to_string(kVersion)) {
    return Malformed(who, RequestKind::kHello, line,
                     std::string("expected \"OK ") + kName + " " + std::to_string(kVersion) + " ...\"");
  }
  std::map<std::string, std::string> values;
  for (size_t i = 2; i < tokens->size(); ++i) {
    const std::string_view token = (*tokens)[i];
    const size_t equals = token.find('=');
    std::string value;
    if (equals == std::string_view::npos || !PercentDecode(token.substr(equals + 1), &value)) {
      return Malformed(who, RequestKind::kHello, line, "\"" + std::string(token.substr(0, 40)) + "\" is not key=value");
    }
    if (!values.emplace(std::string(token.substr(0, equals)), value).second) {
      return Malformed(who, RequestKind::kHello, line, "key " + std::string(token.substr(0, equals)) + " twice");
    }
  }
  for (const char* key : {"model", "serial", "calibration", "joints", "real"}) {
    if (values.count(key) == 0) return Malformed(who, RequestKind::kHello, line, std::string("no ") + key + "=");
  }
  HelloInfo info;
  info.identity.model = values["model"];
  info.identity.serial = values["serial"];
  info.identity.calibration_id = values["calibration"];
  double joints = 0;
  if (!ParseNumber(values["joints"], &joints) || joints < 1 || joints > 1000 || joints != std::floor(joints)) {
    return Malformed(who, RequestKind::kHello, line, "joints=" + values["joints"] + " is not a joint count");
  }
  info.num_joints = static_cast<int>(joints);
  if (values["real"] != "0" && values["real"] != "1") {
    return Malformed(who, RequestKind::kHello, line, "real=" + values["real"] + " is not 0 or 1");
  }
  info.identity.real_hardware = values["real"] == "1";
  return info;
}

Result<JointLimits> ParseLimitsReply(std::string_view line, int num_joints, const std::string& who) {
  const Result<std::vector<std::string_view>> tokens = OkTokens(line, RequestKind::kLimits, RobotError::kProtocol, who);
  if (!tokens.ok()) return tokens.status();
  const size_t n = static_cast<size_t>(num_joints);
  if (tokens->size() != 3 * n) {
    return Malformed(who, RequestKind::kLimits, line,
                     std::to_string(tokens->size()) + " numbers, expected 3 x " + std::to_string(n) + " joints");
  }
  Eigen::VectorXd values;
  std::string bad;
  if (!ParseNumbers(*tokens, 0, &values, &bad)) return Malformed(who, RequestKind::kLimits, line, "\"" + bad + "\" is not a number");
  JointLimits limits;
  limits.lower_rad = values.segment(0, num_joints);
  limits.upper_rad = values.segment(num_joints, num_joints);
  limits.max_velocity_rad_s = values.segment(2 * num_joints, num_joints);
  return limits;
}

Result<JointReading> ParseJointsReply(std::string_view line, const std::string& who) {
  const Result<std::vector<std::string_view>> tokens = OkTokens(line, RequestKind::kJoints, RobotError::kBadReading, who);
  if (!tokens.ok()) return tokens.status();
  if (tokens->empty() || tokens->size() % 2 != 1) {
    return Malformed(who, RequestKind::kJoints, line, "expected a time and as many velocities as positions");
  }
  Eigen::VectorXd values;
  std::string bad;
  if (!ParseNumbers(*tokens, 0, &values, &bad)) return Malformed(who, RequestKind::kJoints, line, "\"" + bad + "\" is not a number");
  const Eigen::Index n = (values.size() - 1) / 2;
  JointReading reading;
  reading.time_s = values[0];
  reading.position_rad = values.segment(1, n);
  reading.velocity_rad_s = values.segment(1 + n, n);
  return reading;
}

Result<RobotStatus> ParseStatusReply(std::string_view line, const std::string& who) {
  const Result<std::vector<std::string_view>> tokens = OkTokens(line, RequestKind::kStatus, RobotError::kProtocol, who);
  if (!tokens.ok()) return tokens.status();
  if (tokens->empty()) return Malformed(who, RequestKind::kStatus, line, "no state");
  RobotStatus status;
  bool known = false;
  for (const MotionState state : {MotionState::kIdle, MotionState::kMoving, MotionState::kProtectiveStop,
                                  MotionState::kEmergencyStop, MotionState::kFault}) {
    if ((*tokens)[0] == MotionStateName(state)) {
      status.state = state;
      known = true;
    }
  }
  if (!known) return Malformed(who, RequestKind::kStatus, line, "unknown state \"" + std::string((*tokens)[0].substr(0, 40)) + "\"");
  status.message = std::string(RestAfter(line, (*tokens)[0]));
  return status;
}

Status ParseOkReply(std::string_view line, RequestKind request, RobotError fault_error, const std::string& who) {
  const Result<std::vector<std::string_view>> tokens = OkTokens(line, request, fault_error, who);
  if (!tokens.ok()) return tokens.status();
  if (!tokens->empty()) return Malformed(who, request, line, "expected a bare OK");
  return Status::Ok();
}

}  // namespace selfcal::robot::protocol
