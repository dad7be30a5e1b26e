// Fuzz harness: the network robot line protocol (docs/robot-protocol.md), both directions. Each line of the
// input is read as a request (what robot_server gets from selfcal) and as every reply selfcal reads from a
// controller (HELLO, LIMITS for 6 joints, JOINTS, STATUS, OK of MOVE and STOP); a request that parses is
// formatted again and must parse to the same request.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "robot/line_protocol.h"

namespace protocol = selfcal::robot::protocol;

namespace {

void CheckMoveRoundTrip(const protocol::Request& request) {
  if (request.kind != protocol::RequestKind::kMove) return;
  const std::string line = protocol::MoveRequest(request.target_rad, request.velocity_scaling);
  selfcal::Result<protocol::Request> again = protocol::ParseRequest(line);
  if (!again.ok() || again->target_rad.size() != request.target_rad.size() ||
      !(again->target_rad.array() == request.target_rad.array()).all() ||
      again->velocity_scaling != request.velocity_scaling) {
    std::fprintf(stderr, "MOVE round trip failed: %s\n", line.c_str());
    std::abort();
  }
}

void OneLine(std::string_view line) {
  const std::string who = "controller";
  selfcal::Result<protocol::Request> request = protocol::ParseRequest(line);
  if (request.ok()) CheckMoveRoundTrip(*request);
  (void)protocol::ParseHelloReply(line, who);
  (void)protocol::ParseLimitsReply(line, 6, who);
  (void)protocol::ParseJointsReply(line, who);
  (void)protocol::ParseStatusReply(line, who);
  (void)protocol::ParseOkReply(line, protocol::RequestKind::kMove, selfcal::robot::RobotError::kRejected, who);
  (void)protocol::ParseOkReply(line, protocol::RequestKind::kStop, selfcal::robot::RobotError::kRejected, who);
  std::string decoded;
  for (std::string_view token : protocol::SplitTokens(line)) (void)protocol::PercentDecode(token, &decoded);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = selfcal::fuzz::AsText(data, size);
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    OneLine(std::string_view(text).substr(start, end - start));
    start = end + 1;
  }
  return 0;
}
