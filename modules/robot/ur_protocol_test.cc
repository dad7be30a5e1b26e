// The UR codec against bytes computed by hand from the RTDE guide and the client interface reference
// (big-endian; the RTDE header's size counts the header; IEEE-754 doubles).
#include "robot/ur_protocol.h"

#include <gtest/gtest.h>

namespace selfcal::robot::ur {
namespace {

std::string Bytes(std::initializer_list<int> values) {
  std::string out;
  for (int v : values) out.push_back(static_cast<char>(v));
  return out;
}

TEST(UrProtocolTest, ProtocolVersionRequestIsTheGuidesFiveBytes) {
  EXPECT_EQ(ProtocolVersionRequest(2), Bytes({0x00, 0x05, 'V', 0x00, 0x02}));
  EXPECT_EQ(*RtdePackageSize(Bytes({0x00, 0x05, 'V'})), 5);
  EXPECT_EQ(RobotErrorOf(RtdePackageSize(Bytes({0x00, 0x02, 'V'})).status()), RobotError::kProtocol);
}

TEST(UrProtocolTest, SetupOutputsCarriesTheFrequencyAsABigEndianDouble) {
  // 125.0 = 0x405F400000000000; size 3 + 8 + 8 ("actual_q") = 19.
  const std::string expected = Bytes({0x00, 0x13, 'O', 0x40, 0x5F, 0x40, 0, 0, 0, 0, 0}) + "actual_q";
  EXPECT_EQ(SetupOutputsRequest(125.0, {"actual_q"}), expected);
  const Result<SetupOutputsReply> reply = ParseSetupOutputsReply(Bytes({0x01}) + "VECTOR6D,NOT_FOUND");
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->recipe_id, 1);
  EXPECT_EQ(reply->types, (std::vector<std::string>{"VECTOR6D", "NOT_FOUND"}));
  EXPECT_FALSE(ParseSetupOutputsReply("").ok());
  EXPECT_TRUE(*ParseAccepted(Bytes({1}), "start"));
  EXPECT_FALSE(*ParseAccepted(Bytes({0}), "start"));
  EXPECT_FALSE(ParseAccepted(Bytes({1, 1}), "start").ok());
}

TEST(UrProtocolTest, StateDataEncodesInRecipeOrderAndRoundTrips) {
  UrState state;
  state.q_rad << 1.0, -2.0, 0.5, 0, 0, 0;
  state.qd_rad_s << 0, 0, 0, 0, 0, 0.25;
  state.runtime_state = 2;
  state.safety_status_bits = kSafetyProtectiveStopped;
  state.robot_status_bits = 3;
  const std::string payload = EncodeStateData(7, state);
  ASSERT_EQ(payload.size(), 1u + 96 + 12);
  EXPECT_EQ(payload.substr(0, 9), Bytes({7, 0x3F, 0xF0, 0, 0, 0, 0, 0, 0}));    // recipe 7, 1.0
  EXPECT_EQ(payload.substr(9, 8), Bytes({0xC0, 0x00, 0, 0, 0, 0, 0, 0}));       // -2.0
  EXPECT_EQ(payload.substr(1 + 88, 8), Bytes({0x3F, 0xD0, 0, 0, 0, 0, 0, 0}));  // qd[5] 0.25
  EXPECT_EQ(payload.substr(97, 12), Bytes({0, 0, 0, 2, 0, 0, 0, 4, 0, 0, 0, 3}));
  const Result<UrState> back = DecodeStateData(payload, 7);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->q_rad, state.q_rad);
  EXPECT_EQ(back->qd_rad_s, state.qd_rad_s);
  EXPECT_EQ(back->runtime_state, 2u);
  EXPECT_EQ(back->safety_status_bits, kSafetyProtectiveStopped);
  EXPECT_EQ(back->robot_status_bits, 3u);
  EXPECT_EQ(RobotErrorOf(DecodeStateData(payload, 8).status()), RobotError::kProtocol);  // another recipe
  EXPECT_EQ(RobotErrorOf(DecodeStateData(payload.substr(0, 50), 7).status()), RobotError::kProtocol);
}

TEST(UrProtocolTest, SafetyBitsGiveTheMotionState) {
  UrState state;
  EXPECT_EQ(StatusOfState(state).state, MotionState::kIdle);
  state.safety_status_bits = kSafetyProtectiveStopped;
  EXPECT_EQ(StatusOfState(state).state, MotionState::kProtectiveStop);
  EXPECT_NE(StatusOfState(state).message.find("protective stop"), std::string::npos);
  state.safety_status_bits = kSafetyRobotEmergencyStopped;
  EXPECT_EQ(StatusOfState(state).state, MotionState::kEmergencyStop);
  state.safety_status_bits = kSafetyFault;
  EXPECT_EQ(StatusOfState(state).state, MotionState::kFault);
  state.safety_status_bits = kSafetyNormal;
  state.robot_status_bits = 0;
  EXPECT_EQ(StatusOfState(state).state, MotionState::kFault);
}

TEST(UrProtocolTest, KinematicsInfoIsFoundInARobotStateMessage) {
  KinematicsInfo info;
  info.checksum = {1, 2, 3, 4, 5, 0xdeadbeef};
  info.dh_d = {0.1625, 0, 0, 0.1333, 0.0997, 0.0996};
  info.dh_a = {0, -0.425, -0.3922, 0, 0, 0};
  info.dh_alpha = {1.5, 0, 0, 1.5, -1.5, 0};
  info.dh_theta = {1e-5, 0, 0, 0, 0, 0};
  info.calibration_status = 1;
  const std::string message = EncodeRobotStateMessage(info);
  // 5 (header) + 9 (a 4-byte placeholder sub-package) + 225 (kinematics info of six joints) = 239.
  ASSERT_EQ(message.size(), 239u);
  EXPECT_EQ(message.substr(0, 5), Bytes({0, 0, 0, 239, 16}));
  EXPECT_EQ(message.substr(14, 9), Bytes({0, 0, 0, 225, 5, 0, 0, 0, 1}));  // size, type 5, checksum[0]
  EXPECT_EQ(*PrimaryMessageSize(message.substr(0, 5)), 239u);
  const Result<std::optional<KinematicsInfo>> back = KinematicsInfoOf(message);
  ASSERT_TRUE(back.ok() && back->has_value());
  EXPECT_EQ((*back)->checksum, info.checksum);
  EXPECT_EQ((*back)->dh_d, info.dh_d);
  EXPECT_EQ((*back)->dh_a, info.dh_a);
  EXPECT_EQ((*back)->dh_theta, info.dh_theta);
  EXPECT_EQ((*back)->calibration_status, 1u);
  EXPECT_EQ(CalibrationIdOf(info), "ur-kinematics-00000001-00000002-00000003-00000004-00000005-deadbeef");
  // Cut inside the kinematics info: its length runs past the message.
  EXPECT_EQ(RobotErrorOf(KinematicsInfoOf(message.substr(0, 100)).status()), RobotError::kProtocol);
  // Another message type: no kinematics, no error.
  std::string version = message;
  version[4] = 20;
  EXPECT_FALSE(KinematicsInfoOf(version)->has_value());
  EXPECT_FALSE(PrimaryMessageSize(Bytes({0, 0, 0, 4, 16})).ok());
}

TEST(UrProtocolTest, UrScriptLinesRoundTrip) {
  Eigen::VectorXd q(6);
  q << 0.1, -1.5707963268, 1.25, -0.5, 0, 3.0;
  const std::string line = MovejScript(q, 1.2, 0.3);
  EXPECT_EQ(line, "movej([0.1000000000, -1.5707963268, 1.2500000000, -0.5000000000, 0.0000000000, 3.0000000000], "
                  "a=1.200000, v=0.300000)");
  double v = 0;
  const std::optional<Eigen::VectorXd> back = ParseMovej(line, &v);
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->isApprox(q, 1e-12));
  EXPECT_DOUBLE_EQ(v, 0.3);
  EXPECT_FALSE(ParseMovej("movej([0, 0, 0], a=1, v=1)", &v).has_value());
  EXPECT_FALSE(ParseMovej("movej([nan, 0, 0, 0, 0, 0], a=1, v=1)", &v).has_value());
  EXPECT_EQ(StopjScript(3.0), "stopj(3.000000)");
  EXPECT_EQ(DashboardValue("Safetystatus: PROTECTIVE_STOP", "Safetystatus:"), "PROTECTIVE_STOP");
  EXPECT_EQ(DashboardValue("nonsense", "Robotmode:"), "");
}

}  // namespace
}  // namespace selfcal::robot::ur
