// The RMI codec against packets written by hand from the packet layouts of FANUC's RMI manual
// (B-84184EN/03, as its Apache-2.0 reference client states them): key names, kinds, degrees on the wire.
#include "robot/fanuc_protocol.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace selfcal::robot::fanuc {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(FanucProtocolTest, RequestsAreTheManualsPackets) {
  EXPECT_EQ(SimpleRequest(PacketKind::kCommunication, "FRC_Connect"), R"({"Communication":"FRC_Connect"})");
  EXPECT_EQ(SimpleRequest(PacketKind::kCommand, "FRC_Abort"), R"({"Command":"FRC_Abort"})");
  Eigen::VectorXd q(6);
  q << kPi / 2, -kPi / 4, 0, 0, kPi, 0;
  const nlohmann::json move = nlohmann::json::parse(JointMotionRequest(7, q, 25));
  EXPECT_EQ(move["Instruction"], "FRC_JointMotionJRep");
  EXPECT_EQ(move["SequenceID"], 7);
  EXPECT_EQ(move["SpeedType"], "Percent");
  EXPECT_EQ(move["Speed"], 25);
  EXPECT_EQ(move["TermType"], "FINE");
  EXPECT_NEAR(move["JointAngle"]["J1"].get<double>(), 90.0, 1e-9);  // degrees on the wire
  EXPECT_NEAR(move["JointAngle"]["J2"].get<double>(), -45.0, 1e-9);
  EXPECT_NEAR(move["JointAngle"]["J5"].get<double>(), 180.0, 1e-9);
  EXPECT_EQ(move["JointAngle"]["J9"].get<double>(), 0.0);
  const std::optional<JointMotion> back = ParseJointMotion(JointMotionRequest(7, q, 25));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->sequence_id, 7);
  EXPECT_EQ(back->speed_percent, 25);
  EXPECT_NEAR((back->target_rad - q).cwiseAbs().maxCoeff(), 0, 1e-12);
  EXPECT_FALSE(ParseJointMotion(R"({"Instruction":"FRC_JointMotion","SequenceID":1})").has_value());
}

TEST(FanucProtocolTest, ConnectAnswerNamesTheSessionPort) {
  const Result<Packet> p =
      ParsePacket(R"({"Communication": "FRC_Connect", "ErrorID": 0, "PortNumber": 16002, "MajorVersion": 1, "MinorVersion": 0})");
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_EQ(p->kind, PacketKind::kCommunication);
  EXPECT_EQ(p->port, 16002);
  EXPECT_EQ(p->major_version, 1);
  EXPECT_EQ(RobotErrorOf(ParsePacket(R"({"Communication":"FRC_Connect","ErrorID":0,"PortNumber":0})").status()),
            RobotError::kProtocol);
  // Refused: no port needed.
  EXPECT_EQ(ParsePacket(R"({"Communication":"FRC_Connect","ErrorID":2556929})")->error_id, 2556929);
}

TEST(FanucProtocolTest, JointAnglesAreReadInDegreesAndChecked) {
  const Result<Packet> p = ParsePacket(
      R"({"Command":"FRC_ReadJointAngles","ErrorID":0,"TimeTag":1234,"JointAngle":{"J1":90.0,"J2":-30.5,"J3":10,)"
      R"("J4":0.0,"J5":-90.0,"J6":180.0,"J7":0.0,"J8":0.0,"J9":0.0}})");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_TRUE(p->joints_rad.has_value());
  EXPECT_NEAR((*p->joints_rad)[0], kPi / 2, 1e-12);
  EXPECT_NEAR((*p->joints_rad)[1], -30.5 * kPi / 180, 1e-12);
  EXPECT_NEAR((*p->joints_rad)[5], kPi, 1e-12);
  const Result<Packet> missing =
      ParsePacket(R"({"Command":"FRC_ReadJointAngles","ErrorID":0,"JointAngle":{"J1":1,"J2":2,"J3":3,"J4":4,"J5":5}})");
  EXPECT_EQ(RobotErrorOf(missing.status()), RobotError::kProtocol);
  EXPECT_NE(missing.status().message().find("J6"), std::string::npos) << missing.status().message();
}

TEST(FanucProtocolTest, StatusSaysWhatHoldsTheArm) {
  const Result<Packet> p = ParsePacket(
      R"({"Command":"FRC_GetStatus","ErrorID":0,"ServoReady":1,"TPMode":0,"RMIMotionStatus":0,"ProgramStatus":0,)"
      R"("SingleStepMode":0,"NumberUTool":1,"NextSequenceID":1,"NumberUFrame":0,"Override":100})");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_TRUE(p->status.has_value());
  EXPECT_EQ(StatusOf(*p->status).state, MotionState::kIdle);
  ControllerStatus off = *p->status;
  off.servo_ready = 0;
  EXPECT_EQ(StatusOf(off).state, MotionState::kFault);
  EXPECT_NE(StatusOf(off).message.find("servos are not ready"), std::string::npos);
  ControllerStatus pendant = *p->status;
  pendant.tp_mode = 1;
  EXPECT_NE(StatusOf(pendant).message.find("teach pendant is enabled"), std::string::npos);
  EXPECT_EQ(RobotErrorOf(ParsePacket(R"({"Command":"FRC_GetStatus","ErrorID":0,"ServoReady":1})").status()),
            RobotError::kProtocol);
}

TEST(FanucProtocolTest, InstructionAnswersAndFaultsCarryTheirSequence) {
  const Result<Packet> done = ParsePacket(R"({"Instruction":"FRC_JointMotionJRep","ErrorID":0,"SequenceID":3})");
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->kind, PacketKind::kInstruction);
  EXPECT_EQ(done->sequence_id, 3);
  const Result<Packet> fault = ParsePacket(R"({"Communication":"FRC_SystemFault","SequenceID":4})");
  ASSERT_TRUE(fault.ok());
  EXPECT_EQ(fault->name, "FRC_SystemFault");
  EXPECT_EQ(fault->sequence_id, 4);
  EXPECT_EQ(ParsePacket(R"({"Command":"Unknown","ErrorID":2556929})")->name, "Unknown");
}

TEST(FanucProtocolTest, MalformedPacketsAreProtocolErrorsWithEscapedText) {
  for (const char* bad : {"", "not json", "[1,2]", R"({"ErrorID":0})", R"({"Command":"A","Instruction":"B"})",
                          R"({"Command":5})", R"({"Command":"FRC_Abort","ErrorID":"x"})",
                          R"({"Instruction":"FRC_JointMotionJRep","SequenceID":1.5})"}) {
    EXPECT_EQ(RobotErrorOf(ParsePacket(bad).status()), RobotError::kProtocol) << bad;
  }
  const Status s = ParsePacket("\x1b[2J").status();
  EXPECT_EQ(s.message().find('\x1b'), std::string::npos) << s.message();
}

TEST(FanucProtocolTest, FakeSideRepliesParseBack) {
  Eigen::VectorXd q(6);
  q << 0.1, -0.2, 0.3, -0.4, 0.5, -0.6;
  EXPECT_NEAR((*ParsePacket(JointAnglesReply(q, 1))->joints_rad - q).cwiseAbs().maxCoeff(), 0, 1e-12);
  ControllerStatus s;
  s.servo_ready = 1;
  s.next_sequence_id = 9;
  EXPECT_EQ(ParsePacket(StatusReply(s))->status->next_sequence_id, 9);
  EXPECT_EQ(ParsePacket(ConnectReply(0, 40000, 1, 2))->port, 40000);
  EXPECT_EQ(ParsePacket(Reply(PacketKind::kInstruction, "FRC_JointMotionJRep", 0, 5))->sequence_id, 5);
  EXPECT_EQ(ParsePacket(SystemFault(6))->sequence_id, 6);
}

}  // namespace
}  // namespace selfcal::robot::fanuc
