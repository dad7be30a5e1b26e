#include "base/json_lines.h"

#include <string>

#include <gtest/gtest.h>

namespace selfcal {
namespace {

TEST(JsonLines, EveryMemberAndElementHasTheLineOfItsKeyOrFirstCharacter) {
  const std::string text =
      "\n"                                   // 1
      "{\n"                                  // 2
      "  \"format\": \"x\",\n"               // 3
      "  \"camera\": {\n"                    // 4
      "    \"fx_px\": 800, \"mu\": 1\n"      // 5
      "  },\n"                               // 6
      "  \"list\": [\n"                      // 7
      "    {\"a\": 1},\n"                    // 8
      "    [],\n"                            // 9
      "    \"s,]}\\\"\"\n"                   // 10
      "  ],\n"                               // 11
      "  \"a/b~c\": null, \"\\u0041\": true\n"  // 12
      "}\n";
  const JsonLines lines(text);
  EXPECT_EQ(lines.Line(""), 2);
  EXPECT_EQ(lines.Line("/format"), 3);
  EXPECT_EQ(lines.Line("/camera"), 4);
  EXPECT_EQ(lines.Line("/camera/fx_px"), 5);
  EXPECT_EQ(lines.Line("/camera/mu"), 5);
  EXPECT_EQ(lines.Line("/list"), 7);
  EXPECT_EQ(lines.Line("/list/0"), 8);
  EXPECT_EQ(lines.Line("/list/0/a"), 8);
  EXPECT_EQ(lines.Line("/list/1"), 9);
  EXPECT_EQ(lines.Line("/list/2"), 10);
  EXPECT_EQ(lines.Line(JsonLines::Member("", "a/b~c")), 12);
  EXPECT_EQ(JsonLines::Member("", "a/b~c"), "/a~1b~0c");
  EXPECT_EQ(lines.Line("/A"), 12);  // the key as nlohmann decodes it
  // Missing keys and elements: the line of the deepest ancestor the document holds.
  EXPECT_EQ(lines.Line("/camera/k1"), 4);
  EXPECT_EQ(lines.Line("/list/7/name"), 7);
  EXPECT_EQ(lines.Line("/nothing/at/all"), 2);
  EXPECT_EQ(lines.Line("not a pointer"), 2);
}

TEST(JsonLines, ARepeatedKeyHasTheLineOfTheLastAsNlohmannKeepsTheLastValue) {
  const JsonLines lines("{\"a\": 1,\n\"a\": 2}");
  EXPECT_EQ(lines.Line("/a"), 2);
}

TEST(JsonLines, TextThatIsNotJsonKeepsTheLinesReadBeforeTheFault) {
  const JsonLines lines("{\n\"a\": 1,\n\"b\" 2,\n\"c\": 3}");
  EXPECT_EQ(lines.Line("/a"), 2);
  EXPECT_EQ(lines.Line("/b"), 3);
  EXPECT_EQ(lines.Line("/c"), 1);
  EXPECT_EQ(JsonLines("").Line("/x"), 1);
  EXPECT_EQ(JsonLines("\n\n  ").Line(""), 3);
  EXPECT_EQ(JsonLines("{\"unterminated").Line("/unterminated"), 1);
}

TEST(JsonLines, DeepNestingIsScannedWithoutRecursionAndRecordedUpTo64Levels) {
  const std::string deep = std::string(200000, '[') + "\n1" + std::string(200000, ']');
  const JsonLines lines(deep);
  std::string pointer;
  for (int i = 0; i < 64; ++i) pointer += "/0";
  EXPECT_EQ(lines.Line(pointer), 1);
  EXPECT_EQ(lines.Line(pointer + "/0/0"), 1);  // recorded under the 64th level
  const JsonLines shallow("[[\n[\n1]]]");
  EXPECT_EQ(shallow.Line("/0/0"), 2);
  EXPECT_EQ(shallow.Line("/0/0/0"), 3);
}

TEST(JsonLines, LineOfAnOffsetAndOfTheFirstValue) {
  EXPECT_EQ(LineOfOffset("ab\ncd\n", 0), 1);
  EXPECT_EQ(LineOfOffset("ab\ncd\n", 3), 2);
  EXPECT_EQ(LineOfOffset("ab\ncd\n", 100), 3);
  EXPECT_EQ(FirstValueLine(""), 1);
  EXPECT_EQ(FirstValueLine(" \r\n\t\n 5"), 3);
}

}  // namespace
}  // namespace selfcal
