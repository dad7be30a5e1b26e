// Fuzz harness: the Remote Motion Interface packets the FANUC backend and its fake read
// (robot/fanuc_protocol.h, docs/fanuc.md). The input is read line by line, each line as a received packet
// and as a joint motion instruction. A packet with joint angles or a controller status that parses must
// give the same values back through the fake's encoders; an instruction that parses must encode back to
// the same target and speed.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_support.h"
#include "robot/fanuc_protocol.h"

namespace fanuc = selfcal::robot::fanuc;

namespace {

void Fail(const char* what) {
  std::fprintf(stderr, "%s\n", what);
  std::abort();
}

void OneLine(const std::string& line) {
  selfcal::Result<fanuc::Packet> packet = fanuc::ParsePacket(line);
  if (packet.ok() && packet->joints_rad) {
    selfcal::Result<fanuc::Packet> again = fanuc::ParsePacket(fanuc::JointAnglesReply(*packet->joints_rad, 0));
    if (!again.ok() || !again->joints_rad || (*again->joints_rad - *packet->joints_rad).cwiseAbs().maxCoeff() > 1e-9 *
                                                    (1 + packet->joints_rad->cwiseAbs().maxCoeff())) {
      Fail("FRC_ReadJointAngles round trip failed");
    }
  }
  if (packet.ok() && packet->status) {
    (void)fanuc::StatusOf(*packet->status);
    selfcal::Result<fanuc::Packet> again = fanuc::ParsePacket(fanuc::StatusReply(*packet->status));
    if (!again.ok() || !again->status || again->status->servo_ready != packet->status->servo_ready ||
        again->status->next_sequence_id != packet->status->next_sequence_id) {
      Fail("FRC_GetStatus round trip failed");
    }
  }
  const std::optional<fanuc::JointMotion> motion = fanuc::ParseJointMotion(line);
  if (motion) {
    const std::optional<fanuc::JointMotion> again =
        fanuc::ParseJointMotion(fanuc::JointMotionRequest(motion->sequence_id, motion->target_rad, motion->speed_percent));
    if (!again || again->sequence_id != motion->sequence_id || again->speed_percent != motion->speed_percent ||
        (again->target_rad - motion->target_rad).cwiseAbs().maxCoeff() > 1e-9 * (1 + motion->target_rad.cwiseAbs().maxCoeff())) {
      Fail("FRC_JointMotionJRep round trip failed");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = selfcal::fuzz::AsText(data, size);
  size_t start = 0;
  while (start <= bytes.size()) {
    const size_t end = std::min(bytes.find('\n', start), bytes.size());
    OneLine(bytes.substr(start, end - start));
    start = end + 1;
  }
  return 0;
}
