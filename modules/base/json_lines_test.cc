#include "base/json_lines.h"

#include <optional>
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

TEST(JsonLines, TheFirstKeyGivenTwiceInOneObjectIsFoundWithBothLines) {
  const std::string text =
      "{\n"                                 // 1
      "  \"a\": {\"x\": 1, \"y\": 2},\n"        // 2
      "  \"b\": [{\"x\": 1}, {\"x\": 2}],\n"    // 3: the same key in two objects is no repeat
      "  \"c\": {\"x\": 1,\n"                 // 4
      "        \"\\u0078\": 2},\n"             // 5: "x" written with an escape
      "  \"a\": 3\n"                          // 6
      "}\n";
  const JsonLines lines(text);
  ASSERT_TRUE(lines.duplicate().has_value());
  EXPECT_EQ(lines.duplicate()->pointer, "/c/x");
  EXPECT_EQ(lines.duplicate()->line, 5);
  EXPECT_EQ(lines.duplicate()->first_line, 4);
  const std::optional<JsonDuplicateKey> found = FindDuplicateJsonKey(text);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->pointer, "/c/x");
  EXPECT_EQ(DuplicateKeyProblem(*found),
            "`c.x` is given twice (lines 4 and 5): a JSON reader would keep one of them without a word; keep one");
  EXPECT_FALSE(JsonLines("{\"a\": {\"x\": 1}, \"b\": {\"x\": 1}, \"l\": [1, 1]}").duplicate().has_value());
  EXPECT_FALSE(FindDuplicateJsonKey("[{\"x\": 1}, {\"x\": 1}]").has_value());
  // Deeper than the recorded depth too.
  std::string deep;
  for (int i = 0; i < 100; ++i) deep += "{\"k\": ";
  deep += "{\"z\": 1, \"z\": 2}";
  for (int i = 0; i < 100; ++i) deep += "}";
  EXPECT_TRUE(FindDuplicateJsonKey(deep).has_value());
}

TEST(JsonLines, PointersReadAsDottedNames) {
  EXPECT_EQ(JsonPointerName(""), "");
  EXPECT_EQ(JsonPointerName("/camera/fx_px"), "camera.fx_px");
  EXPECT_EQ(JsonPointerName("/inputs/2/name"), "inputs[2].name");
  EXPECT_EQ(JsonPointerName("/a~1b~0c"), "a/b~c");
}

}  // namespace
}  // namespace selfcal
