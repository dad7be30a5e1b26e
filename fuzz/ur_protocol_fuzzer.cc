// Fuzz harness: the Universal Robots byte formats the UR backend reads (robot/ur_protocol.h,
// docs/universal-robots.md). The input is read as an RTDE stream (3-byte headers and payloads: every
// payload decoded as a state data package, a recipe setup answer and an accepted flag), as one primary
// interface message (its kinematics info) and, line by line, as movej scripts. A state package that
// decodes is encoded again and must give its bytes back.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_support.h"
#include "robot/ur_protocol.h"

namespace ur = selfcal::robot::ur;

namespace {

void OnePayload(const std::string& payload) {
  selfcal::Result<ur::UrState> state = ur::DecodeStateData(payload, 1);
  if (state.ok() && ur::EncodeStateData(1, *state) != payload) {
    std::fprintf(stderr, "RTDE state data round trip failed\n");
    std::abort();
  }
  if (state.ok()) (void)ur::StatusOfState(*state);
  (void)ur::ParseSetupOutputsReply(payload);
  (void)ur::ParseAccepted(payload, "fuzz");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = selfcal::fuzz::AsText(data, size);
  for (size_t at = 0; at + 3 <= bytes.size();) {
    selfcal::Result<uint16_t> length = ur::RtdePackageSize(bytes.substr(at, 3));
    if (!length.ok() || at + *length > bytes.size()) break;
    OnePayload(bytes.substr(at + 3, *length - 3));
    at += *length;
  }
  if (bytes.size() >= 5 && ur::PrimaryMessageSize(bytes.substr(0, 5)).ok()) {
    selfcal::Result<std::optional<ur::KinematicsInfo>> info = ur::KinematicsInfoOf(bytes);
    if (info.ok() && info->has_value()) (void)ur::CalibrationIdOf(**info);
  }
  size_t start = 0;
  while (start <= bytes.size()) {
    const size_t end = std::min(bytes.find('\n', start), bytes.size());
    double velocity = 0;
    (void)ur::ParseMovej(bytes.substr(start, end - start), &velocity);
    (void)ur::DashboardValue(bytes.substr(start, end - start), "Safetystatus:");
    start = end + 1;
  }
  return 0;
}
