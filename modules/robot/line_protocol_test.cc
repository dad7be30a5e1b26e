// Lines of the robot protocol (docs/robot-protocol.md): numbers to the bit in any locale, identity
// tokens, requests, replies and the ERR codes.
#include "robot/line_protocol.h"

#include <clocale>
#include <cmath>
#include <cstring>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/robot_test_util.h"

namespace selfcal::robot::protocol {
namespace {

using ::testing::HasSubstr;

const std::string kWho = "test";

TEST(LineProtocolNumbers, RoundTripToTheBit) {
  const double values[] = {0.0, -0.0, 0.1, 1.0 / 3, -2.0943951023931953, 3.141592653589793, 1e-300, 4.9e-324,
                           1.7976931348623157e308, 123456789.123456789, -1e22};
  for (const double value : values) {
    double parsed = 0;
    ASSERT_TRUE(ParseNumber(FormatNumber(value), &parsed)) << FormatNumber(value);
    EXPECT_EQ(std::memcmp(&parsed, &value, sizeof(double)), 0) << FormatNumber(value);
    char printf_text[64];
    std::snprintf(printf_text, sizeof(printf_text), "%.17g", value);
    EXPECT_EQ(FormatNumber(value), printf_text);
  }
  EXPECT_EQ(FormatNumber(0.1), "0.10000000000000001");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::infinity()), "inf");
  double parsed = 0;
  EXPECT_TRUE(ParseNumber("nan", &parsed));
  EXPECT_TRUE(std::isnan(parsed));
  EXPECT_TRUE(ParseNumber("-inf", &parsed));
  EXPECT_EQ(parsed, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(ParseNumber("+1.5e3", &parsed));
  EXPECT_EQ(parsed, 1500);
  for (const char* bad : {"", "+", "1.0x", "1,5", "0x10", "1e999", "- 1", "one"}) {
    EXPECT_FALSE(ParseNumber(bad, &parsed)) << bad;
  }
}

TEST(LineProtocolNumbers, IndependentOfTheProcessLocale) {
  const char* previous = std::setlocale(LC_NUMERIC, nullptr);
  const std::string saved = previous != nullptr ? previous : "C";
  if (std::setlocale(LC_NUMERIC, "de_DE.UTF-8") == nullptr && std::setlocale(LC_NUMERIC, "fr_FR.UTF-8") == nullptr) {
    GTEST_SKIP() << "no locale with a decimal comma installed";
  }
  const std::string text = FormatNumber(0.5);
  double parsed = 0;
  const bool ok = ParseNumber("0.25", &parsed);
  std::setlocale(LC_NUMERIC, saved.c_str());
  EXPECT_EQ(text, "0.5");
  EXPECT_TRUE(ok);
  EXPECT_EQ(parsed, 0.25);
}

TEST(LineProtocolTokens, PercentEncodingRoundTrips) {
  const std::string text = "cal 2024/05 = 100% \xc3\xa9\tx";
  const std::string encoded = PercentEncode(text);
  EXPECT_EQ(encoded, "cal%202024/05%20%3D%20100%25%20%C3%A9%09x");
  std::string decoded;
  ASSERT_TRUE(PercentDecode(encoded, &decoded));
  EXPECT_EQ(decoded, text);
  EXPECT_FALSE(PercentDecode("a%4", &decoded));
  EXPECT_FALSE(PercentDecode("a%G1", &decoded));
  EXPECT_EQ(SplitTokens("  OK  a b "), (std::vector<std::string_view>{"OK", "a", "b"}));
}

TEST(LineProtocolRequests, ParseEveryRequest) {
  EXPECT_EQ(ParseRequest(HelloRequest())->kind, RequestKind::kHello);
  EXPECT_EQ(ParseRequest("JOINTS")->kind, RequestKind::kJoints);
  EXPECT_EQ(ParseRequest("BYE")->kind, RequestKind::kBye);
  const Eigen::Vector3d target(0.1, -1.0 / 3, 2.5);
  const Result<Request> move = ParseRequest(MoveRequest(target, 0.25));
  ASSERT_TRUE(move.ok());
  EXPECT_EQ(move->kind, RequestKind::kMove);
  EXPECT_EQ(move->velocity_scaling, 0.25);
  EXPECT_EQ(move->target_rad, Eigen::VectorXd(target));
  EXPECT_THAT(ParseRequest("FLY").status().message(), HasSubstr("unknown request \"FLY\""));
  EXPECT_THAT(ParseRequest("HELLO selfcal-robot 2").status().message(), HasSubstr("unsupported protocol"));
  EXPECT_THAT(ParseRequest("STATUS now").status().message(), HasSubstr("STATUS takes no arguments"));
  EXPECT_THAT(ParseRequest("MOVE 1").status().message(), HasSubstr("MOVE needs a scaling"));
  EXPECT_THAT(ParseRequest("MOVE 1 0.1 abc").status().message(), HasSubstr("\"abc\" is not a number"));
  EXPECT_FALSE(ParseRequest("").ok());
  EXPECT_FALSE(ParseRequest("joints").ok());  // words are upper case
}

TEST(LineProtocolReplies, HelloLimitsJointsStatusRoundTrip) {
  RobotIdentity identity{"simulated", "puma 560", "sim-7", "cal=3", true};
  const Result<HelloInfo> hello = ParseHelloReply(HelloReply(identity, 6), kWho);
  ASSERT_TRUE(hello.ok()) << hello.status().ToString();
  EXPECT_EQ(hello->num_joints, 6);
  EXPECT_EQ(hello->identity.model, "puma 560");
  EXPECT_EQ(hello->identity.serial, "sim-7");
  EXPECT_EQ(hello->identity.calibration_id, "cal=3");
  EXPECT_TRUE(hello->identity.real_hardware);

  const JointLimits limits = robot::testing::ThreeJointOptions().limits;
  const Result<JointLimits> parsed_limits = ParseLimitsReply(LimitsReply(limits), 3, kWho);
  ASSERT_TRUE(parsed_limits.ok());
  EXPECT_EQ(parsed_limits->max_velocity_rad_s, limits.max_velocity_rad_s);
  EXPECT_THAT(ParseLimitsReply(LimitsReply(limits), 4, kWho).status().message(), HasSubstr("expected 3 x 4 joints"));

  JointReading reading;
  reading.time_s = 1234.5678901234567;
  reading.position_rad = Eigen::Vector2d(0.1, std::numeric_limits<double>::quiet_NaN());
  reading.velocity_rad_s = Eigen::Vector2d(-1e-17, 0);
  const Result<JointReading> parsed = ParseJointsReply(JointsReply(reading), kWho);
  ASSERT_TRUE(parsed.ok());
  EXPECT_EQ(parsed->time_s, reading.time_s);
  EXPECT_EQ(parsed->position_rad[0], 0.1);
  EXPECT_TRUE(std::isnan(parsed->position_rad[1]));  // passed on: the caller's checks refuse it (R8)
  EXPECT_EQ(parsed->velocity_rad_s, reading.velocity_rad_s);

  RobotStatus status{MotionState::kProtectiveStop, "collision on\njoint 2"};
  EXPECT_EQ(StatusReply(status), "OK protective_stop collision on joint 2");
  const Result<RobotStatus> parsed_status = ParseStatusReply(StatusReply(status), kWho);
  ASSERT_TRUE(parsed_status.ok());
  EXPECT_EQ(parsed_status->state, MotionState::kProtectiveStop);
  EXPECT_EQ(parsed_status->message, "collision on joint 2");
  EXPECT_EQ(ParseStatusReply("OK idle", kWho)->message, "");
}

TEST(LineProtocolReplies, MalformedRepliesAreProtocolErrorsQuotingTheLine) {
  const auto expect_protocol = [](const Status& status, const std::string& part) {
    EXPECT_EQ(RobotErrorOf(status), RobotError::kProtocol) << status.ToString();
    EXPECT_THAT(status.message(), HasSubstr(part));
  };
  expect_protocol(ParseJointsReply("OK 1 2 3 4", kWho).status(), "test: JOINTS: malformed reply \"OK 1 2 3 4\"");
  expect_protocol(ParseJointsReply("OK 1 x 3", kWho).status(), "\"x\" is not a number");
  expect_protocol(ParseStatusReply("OK flying", kWho).status(), "unknown state \"flying\"");
  expect_protocol(ParseStatusReply("hello world", kWho).status(), "expected OK or ERR");
  expect_protocol(ParseHelloReply("OK selfcal-robot 2 model=a", kWho).status(), "expected \"OK selfcal-robot 1");
  expect_protocol(ParseHelloReply("OK selfcal-robot 1 model=a serial=b calibration= joints=3", kWho).status(), "no real=");
  expect_protocol(ParseHelloReply("OK selfcal-robot 1 model=a serial=b calibration= joints=2.5 real=0", kWho).status(),
                  "joints=2.5 is not a joint count");
  expect_protocol(ParseOkReply("OK 1", RequestKind::kStop, RobotError::kRejected, kWho), "expected a bare OK");
  const std::string long_line = "OK " + std::string(1000, 'x');
  EXPECT_LT(ParseStatusReply(long_line, kWho).status().message().size(), 400u);  // quotes only the start
}

TEST(LineProtocolReplies, ErrCodesMapToRobotErrors) {
  const auto error_of = [](const std::string& line, RobotError fault_error) {
    return RobotErrorOf(ParseOkReply(line, RequestKind::kMove, fault_error, kWho));
  };
  EXPECT_EQ(error_of("ERR rejected joint 2 outside", RobotError::kRejected), RobotError::kRejected);
  EXPECT_EQ(error_of("ERR protective_stop", RobotError::kRejected), RobotError::kProtectiveStop);
  EXPECT_EQ(error_of("ERR emergency_stop pressed", RobotError::kRejected), RobotError::kEmergencyStop);
  EXPECT_EQ(error_of("ERR bad_request what", RobotError::kRejected), RobotError::kProtocol);
  EXPECT_EQ(error_of("ERR fault drive error", RobotError::kBadReading), RobotError::kBadReading);
  EXPECT_EQ(error_of("ERR sideways", RobotError::kRejected), RobotError::kProtocol);
  EXPECT_THAT(ParseOkReply("ERR rejected  joint 2 outside", RequestKind::kMove, RobotError::kRejected, kWho).message(),
              HasSubstr("test: MOVE: controller error rejected: joint 2 outside"));
  EXPECT_EQ(ErrorReply(ErrorCodeFor(RobotError::kEmergencyStop), "a\nb"), "ERR emergency_stop a b");
  EXPECT_STREQ(ErrorCodeFor(RobotError::kBadReading), "fault");
}

}  // namespace
}  // namespace selfcal::robot::protocol
