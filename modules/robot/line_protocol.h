// The selfcal robot line protocol (docs/robot-protocol.md): formatting and parsing of its request and
// reply lines, shared by the client (network_robot.h) and the server (robot_server.h). Pure functions,
// no sockets.
//
// Numbers are written like printf's "%.17g" in the C locale whatever the process locale is (so a double
// survives the round trip to the bit); non-finite values as nan, inf, -inf. Angles in rad, times in s.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "robot/robot.h"

namespace selfcal::robot::protocol {

inline constexpr const char* kName = "selfcal-robot";
inline constexpr int kVersion = 1;
// The longest line either side accepts (without "\n"): a guard against garbage, far above any real line.
inline constexpr size_t kMaxLineBytes = 64 * 1024;

// "%.17g" in the C locale.
std::string FormatNumber(double value);
// The whole token as a number in the C locale ("%.17g" output, also "+1", "1e3", "nan", "inf"); false on
// anything else, including out-of-range values.
bool ParseNumber(std::string_view token, double* value);

// Identity values travel as single tokens: '%', '=' and every byte outside '!'..'~' become %XX.
std::string PercentEncode(std::string_view text);
bool PercentDecode(std::string_view token, std::string* text);

// Tokens separated by runs of spaces.
std::vector<std::string_view> SplitTokens(std::string_view line);

// ---- requests (client -> server)

enum class RequestKind { kHello, kLimits, kJoints, kMove, kStatus, kStop, kBye };
const char* RequestWord(RequestKind kind);  // "HELLO", "LIMITS", ...

struct Request {
  RequestKind kind = RequestKind::kHello;
  double velocity_scaling = 0;  // kMove
  Eigen::VectorXd target_rad;   // kMove: as many values as the line had
};

std::string HelloRequest();  // "HELLO selfcal-robot 1"
std::string MoveRequest(const Eigen::VectorXd& target_rad, double velocity_scaling);
// The request on `line`; an error (its message is the text of the `ERR bad_request` reply) when the word
// is unknown, arguments are missing or extra, a number does not parse, or HELLO names another protocol
// or version.
Result<Request> ParseRequest(std::string_view line);

// ---- replies (server -> client)

// ERR codes.
inline constexpr const char* kErrRejected = "rejected";
inline constexpr const char* kErrProtectiveStop = "protective_stop";
inline constexpr const char* kErrEmergencyStop = "emergency_stop";
inline constexpr const char* kErrBadRequest = "bad_request";
inline constexpr const char* kErrFault = "fault";

// The ERR code a server sends for a failed Robot call: rejected, protective_stop, emergency_stop for those
// errors, fault for any other (a lost connection is not answered: the server closes the socket).
const char* ErrorCodeFor(RobotError error);

std::string OkReply();
// "ERR <code> <text>", line breaks in `text` replaced by spaces.
std::string ErrorReply(std::string_view code, std::string_view text);
// "OK selfcal-robot 1 model=.. serial=.. calibration=.. joints=<n> real=<0|1>"
std::string HelloReply(const RobotIdentity& identity, int num_joints);
std::string LimitsReply(const JointLimits& limits);  // "OK <n lower> <n upper> <n vmax>"
// "OK <t> <n q> <n qdot>" with t = reading.time_s on the controller's clock.
std::string JointsReply(const JointReading& reading);
std::string StatusReply(const RobotStatus& status);  // "OK <state> [text]"

// Parsing replies. Every function refuses a malformed line with kProtocol naming the request and the
// line. An `ERR <code> <text>` reply becomes the RobotError of its code: rejected -> kRejected,
// protective_stop -> kProtectiveStop, emergency_stop -> kEmergencyStop, bad_request -> kProtocol, and
// fault -> `fault_error` (what a controller fault means for this request); an unknown code -> kProtocol.
// `who` (e.g. "network robot 127.0.0.1:5000") starts every message.

struct HelloInfo {
  RobotIdentity identity;  // backend left empty: the client fills it in
  int num_joints = 0;
};
Result<HelloInfo> ParseHelloReply(std::string_view line, const std::string& who);
Result<JointLimits> ParseLimitsReply(std::string_view line, int num_joints, const std::string& who);
// The reading as sent (time_s: the controller's clock). As many joints as the line carries, so that a
// short reading reaches the caller's checks (R8); an odd count of numbers is a protocol error.
Result<JointReading> ParseJointsReply(std::string_view line, const std::string& who);
Result<RobotStatus> ParseStatusReply(std::string_view line, const std::string& who);
// A bare "OK" (MOVE, STOP, BYE).
Status ParseOkReply(std::string_view line, RequestKind request, RobotError fault_error, const std::string& who);

}  // namespace selfcal::robot::protocol
