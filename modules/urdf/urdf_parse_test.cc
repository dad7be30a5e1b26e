// URDF refusals (urdf_parse.h): no crash on any nesting, and every refusal names the file and the line.
#include "urdf/urdf_parse.h"

#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/temp_files.h"
#include "urdf/urdf_robot.h"

namespace selfcal::urdf {
namespace {

std::string Ur5e() { return testing::ReadFile(std::string(SELFCAL_SOURCE_DIR) + "/test/data/urdf/ur5e.urdf"); }
const UrdfChainSpec kWithCamera{"base_link", "tool0", "camera_optical_frame"};

std::string Refusal(const std::string& text) {
  Result<UrdfRobot> robot = ParseUrdfRobot(text, "arm.urdf", kWithCamera, std::nullopt);
  EXPECT_FALSE(robot.ok());
  if (robot.ok()) return "";
  EXPECT_EQ(robot.status().code(), ErrorCode::kInvalidInput);
  return robot.status().message();
}

int LineOf(const std::string& text, const std::string& part) {
  const size_t at = text.find(part);
  EXPECT_NE(at, std::string::npos) << part;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// A URDF followed by 100,000 nested elements crashed tinyxml's recursion (SIGSEGV after 15-21 s): refused
// by the depth limit, naming the file and the line, in well under a second.
TEST(UrdfParse, HundredThousandNestedElementsAreRefusedByLine) {
  std::string text = Ur5e();
  const size_t end = text.rfind("</robot>");
  ASSERT_NE(end, std::string::npos);
  const int line = LineOf(text, "</robot>");
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "<a>";
  for (int i = 0; i < 100000; ++i) deep += "</a>";
  text.insert(end, deep);
  const std::string message = Refusal(text);
  EXPECT_EQ(message, "arm.urdf:" + std::to_string(line) + ": elements nested deeper than 64 levels, the limit for a URDF");
}

TEST(UrdfParse, TooLargeTextNamesItsSizeAndTheLimit) {
  const std::string text = Ur5e() + std::string(kMaxUrdfBytes, ' ');
  EXPECT_EQ(Refusal(text), "arm.urdf is " + std::to_string(text.size()) + " bytes, more than the limit of " +
                               std::to_string(kMaxUrdfBytes) + " bytes for a URDF");
}

// Syntax errors: the line from the scan or from tinyxml (the parser urdfdom uses).
TEST(UrdfParse, SyntaxErrorsNameTheLine) {
  EXPECT_EQ(Refusal("<robot name=\"x\"><link name="), "arm.urdf:1: unterminated tag `<link`: no `>` before the end of the file");
  EXPECT_EQ(Refusal("<robot name=\"x\">\n  <link name=\"a\">\n</robot>\n"),
            "arm.urdf:3: closing tag </robot> does not match <link> (line 2)");
  const std::string twice = "<robot name=\"x\">\n  <link name=\"a\"/>\n  <link name=\"b\" name=\"c\"/>\n</robot>\n";
  EXPECT_EQ(Refusal(twice), "arm.urdf:3: not well-formed XML (tinyxml: Error parsing Element.)");
}

// Issue 36's campaign: a URDF with bytes that are not UTF-8 (in a comment, between elements) was taken;
// XML without another declared encoding is UTF-8, and a URDF declares none.
TEST(UrdfParse, InvalidUtf8IsRefusedByLine) {
  for (const std::string& bad : {std::string("\xc0\xaf"), std::string("\xf8\x88\x80\x80\x80")}) {
    std::string text = Ur5e();
    const size_t at = text.find("<link");
    ASSERT_NE(at, std::string::npos);
    text.insert(at, bad);
    EXPECT_EQ(Refusal(text), "arm.urdf:" + std::to_string(LineOf(text, bad)) + ": invalid UTF-8 (a URDF must be UTF-8)");
  }
}

// urdfdom's own refusals (a model error, not a syntax error): its reason, and the line of the element whose
// name it quotes, instead of "urdfdom could not parse the URDF".
TEST(UrdfParse, UrdfdomModelErrorsNameTheElementAndItsLine) {
  std::string text = Ur5e();
  const std::string child = "<child link=\"link3\"/>";
  const size_t at = text.find(child);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, child.size(), "<child link=\"link_missing\"/>");
  const std::string joint = "<joint name=\"" + std::string("joint3") + "\"";
  const std::string message = Refusal(text);
  EXPECT_EQ(message.rfind("arm.urdf:" + std::to_string(LineOf(text, joint)) + ": the <joint> named `joint3`: urdfdom "
                          "could not read the URDF: ", 0), 0u) << message;
  EXPECT_NE(message.find("link_missing"), std::string::npos) << message;
  // A joint without a type names that joint.
  std::string untyped = Ur5e();
  const std::string typed = "name=\"joint2\" type=\"revolute\"";
  untyped.replace(untyped.find(typed), typed.size(), "name=\"joint2\"");
  const std::string second = Refusal(untyped);
  EXPECT_EQ(second.rfind("arm.urdf:" + std::to_string(LineOf(untyped, "name=\"joint2\"")) + ": the <joint> named `joint2`", 0), 0u)
      << second;
}

// urdfdom takes these without a word (the mutation campaign's urdf-02503 and urdf-02539): a misspelt <axis>
// (the joint turns about x), an axis of 1e23 (it becomes x), an origin of 1e308, a misspelt `upper=` (0 rad).
TEST(UrdfParse, ValuesUrdfdomTakesSilentlyAreRefusedByLine) {
  const std::string joint2 = "name=\"joint2\"";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"<axis xyz=\"0 0 1\"/>", "<aixs xyz=\"0 0 1\"/>"},
      {"<axis xyz=\"0 0 1\"/>", "<axis xyz=\"99999999999999999999999 0 1\"/>"},
      {"<origin xyz=\"0 0 0.1625\"", "<origin xyz=\"0 0 1e308\""},
      {"rpy=\"1.5707963267948966 0 0\"", "rpy=\"1e308 0 0\""},
      {"upper=\"6.283185307179586\"", "upepr=\"6.283185307179586\""},
      {"<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 1\"/><axis xyz=\"1 0 0\"/>"}};  // the campaign's urdf-00559
  const std::vector<std::string> expected = {"<aixs> is not an element of a joint", "1e+23 is beyond the limit",
                                             "1e+308 m is beyond the limit", "1e+308 rad is beyond the limit",
                                             "a revolute joint needs `upper=`", "<axis> is given twice in a joint"};
  for (size_t k = 0; k < cases.size(); ++k) {
    std::string text = Ur5e();
    const size_t line_at = text.find(joint2);
    const size_t at = text.find(cases[k].first, line_at);
    ASSERT_NE(at, std::string::npos) << cases[k].first;
    text.replace(at, cases[k].first.size(), cases[k].second);
    const std::string message = Refusal(text);
    EXPECT_EQ(message.rfind("arm.urdf:" + std::to_string(LineOf(text, joint2)) + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(expected[k]), std::string::npos) << message;
  }
}

// selfcal's own refusals of the chain (a joint it cannot take, a missing link) name the joint's line too, or
// the line of <robot> when the name is not an element of the file.
TEST(UrdfParse, ChainRefusalsNameTheLineOfTheElement) {
  std::string text = Ur5e();
  const std::string revolute = "name=\"joint4\" type=\"revolute\"";
  text.replace(text.find(revolute), revolute.size(), "name=\"joint4\" type=\"prismatic\"");
  EXPECT_EQ(Refusal(text).rfind("arm.urdf:" + std::to_string(LineOf(text, "name=\"joint4\"")) + ": joint `joint4` is prismatic", 0),
            0u) << Refusal(text);
  Result<UrdfRobot> robot = ParseUrdfRobot(Ur5e(), "arm.urdf", {"base_link", "tool9", ""}, Rigid3());
  ASSERT_FALSE(robot.ok());
  EXPECT_EQ(robot.status().message().rfind("arm.urdf:" + std::to_string(LineOf(Ur5e(), "<robot")) +
                                               ": tip_link `tool9` is not a link of robot `ur5e`", 0),
            0u) << robot.status().message();
}

}  // namespace
}  // namespace selfcal::urdf
