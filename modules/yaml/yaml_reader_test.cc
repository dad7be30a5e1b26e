// The strict YAML reader on its own: the tree, its line numbers and the refusals in both wordings. The
// files built on it are tested through their readers (io's MalformedFiles, capture's RecordedSequenceV8).
#include "yaml/yaml_reader.h"

#include <string>

#include <gtest/gtest.h>

#include "support/temp_files.h"

namespace selfcal::yaml {
namespace {

YamlRules IndexRules(int max_depth = 8) {
  YamlRules rules;
  rules.max_depth = max_depth;
  rules.wording = YamlWording::kSequenceIndex;
  return rules;
}

std::string Refusal(const std::string& text, const YamlRules& rules = {}) {
  Result<YamlDocument> doc = ParseYamlText(text, "f.yaml", rules);
  EXPECT_FALSE(doc.ok()) << text;
  if (doc.ok()) return "";
  EXPECT_EQ(doc.status().code(), ErrorCode::kInvalidInput);
  return doc.status().message();
}

TEST(YamlReader, TreeKeepsLinesKeysAndQuoting) {
  Result<YamlDocument> doc = ParseYamlText("# comment\na: 1\nb:\n  - \"x\"\n  - [2, 3]\nc:\n", "f.yaml");
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  const YamlNode& root = doc->root;
  ASSERT_TRUE(root.IsMap());
  EXPECT_EQ(root.keys, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(root.key_lines, (std::vector<int>{2, 3, 6}));
  ASSERT_NE(root.Find("a"), nullptr);
  EXPECT_EQ(root.Find("a")->scalar, "1");
  EXPECT_TRUE(root.Find("a")->plain);
  EXPECT_EQ(root.Find("missing"), nullptr);
  const YamlNode& b = *root.Find("b");
  ASSERT_TRUE(b.IsSequence());
  ASSERT_EQ(b.items.size(), 2u);
  EXPECT_FALSE(b.items[0].plain);
  EXPECT_STREQ(b.items[0].KindName(), "a quoted string");
  EXPECT_EQ(b.items[1].line, 5);
  EXPECT_TRUE(root.Find("c")->IsNull());
  EXPECT_EQ(root.Find("c")->line, 6);  // an empty value carries its key's line
}

TEST(YamlReader, BomAndCrlfAreAcceptedAndLinesCountOnce) {
  Result<YamlDocument> doc = ParseYamlText("\xEF\xBB\xBF" "a: 1\r\nb: 2\r\n", "f.yaml");
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  EXPECT_EQ(doc->root.key_lines, (std::vector<int>{1, 2}));
}

TEST(YamlReader, UserFileRefusalsSayWhereAfterTheProblem) {
  EXPECT_EQ(Refusal("a: 1\nb: &x 2\n"), "YAML anchors (&name) are not supported; write the values out at f.yaml:2");
  EXPECT_EQ(Refusal("a: 1\na: 2\n"), "duplicate key `a` at f.yaml:2");
  EXPECT_EQ(Refusal("a: [[[1]]]\n", YamlRules{kMaxYamlBytes, 2, kMaxYamlNodes, YamlWording::kUserFile, ""}),
            "YAML nested deeper than 2 levels at f.yaml:1");
  EXPECT_NE(Refusal("a: b\x01\n").find("control character U+0001 at f.yaml:1"), std::string::npos);
  EXPECT_NE(Refusal("a: 1\nb: \xC3\x28\n").find("invalid UTF-8 (byte 0xC3) at f.yaml:2"), std::string::npos);
  EXPECT_EQ(Refusal("\xFF\xFE" "a\0"), "a UTF-16 or UTF-32 byte order mark at f.yaml:1: the file is not UTF-8; save it as UTF-8");
  EXPECT_EQ(Refusal("a: 1\n---\nb: 2\n"), "more than one YAML document (a second `---`) at f.yaml:2");
  EXPECT_EQ(Refusal("# only a comment\n"), "no YAML document at f.yaml:1 (the file is empty or holds only comments)");
  EXPECT_EQ(Refusal("a: 12345\n", YamlRules{4, kMaxYamlDepth, kMaxYamlNodes, YamlWording::kUserFile, ""}),
            "f.yaml is 9 bytes, more than the limit of 4 bytes (the limit falls at f.yaml:1)");
  EXPECT_EQ(Refusal("a: 1\nb: 2\nc: 3\n", YamlRules{9, kMaxYamlDepth, kMaxYamlNodes, YamlWording::kUserFile, ""}),
            "f.yaml is 15 bytes, more than the limit of 9 bytes (the limit falls at f.yaml:2)");
  EXPECT_NE(Refusal("a: {\n").find("malformed YAML at f.yaml:"), std::string::npos);
  EXPECT_EQ(Refusal("a: 1\nb: *x\n"), "YAML aliases (*name) are not supported; write the values out at f.yaml:2");
}

TEST(YamlReader, NullsAreEmptyValuesWithTheirLines) {
  Result<YamlDocument> doc = ParseYamlText("a: ~\nb: null\nc: 'null'\nd: NULL\ne:\n  -\n  - Null\n  - ! ~\n", "f.yaml");
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  const YamlNode& root = doc->root;
  EXPECT_TRUE(root.Find("a")->IsNull());
  EXPECT_TRUE(root.Find("b")->IsNull());
  EXPECT_EQ(root.Find("c")->scalar, "null");  // quoted: a string
  EXPECT_FALSE(root.Find("c")->plain);
  EXPECT_TRUE(root.Find("d")->IsNull());
  const YamlNode& e = *root.Find("e");
  ASSERT_EQ(e.items.size(), 3u);
  EXPECT_TRUE(e.items[0].IsNull());
  EXPECT_EQ(e.items[0].line, 6);  // the line of its `-`
  EXPECT_TRUE(e.items[1].IsNull());
  EXPECT_EQ(e.items[1].line, 7);
  EXPECT_EQ(e.items[2].scalar, "~");  // the non-specific tag makes it a string
  EXPECT_FALSE(e.items[2].plain);
  EXPECT_EQ(Refusal("~: 1\n"), "empty map key at f.yaml:1");
}

TEST(YamlReader, MalformedTextNamesTheLineOfItsProblem) {
  // A line that is neither `key: value` nor part of the value before it (yaml-cpp read it as a key).
  EXPECT_EQ(Refusal("a:\n  b\nc\nd: 1\n"),
            "malformed YAML at f.yaml:3: could not find expected ':' (while scanning a simple key)");
  EXPECT_EQ(Refusal("a: [1, , 2]\n"),
            "malformed YAML at f.yaml:1: did not find expected node content (while parsing a flow node)");
  EXPECT_EQ(Refusal("a: 1\nb: \"open\n"),
            "malformed YAML at f.yaml:3: found unexpected end of stream (while scanning a quoted scalar at line 2)");
  EXPECT_EQ(Refusal("a:\n  - 1\n  -\t2\n"), "malformed YAML at f.yaml:3: found character that cannot start any token "
                                                 "(while scanning for the next token); a tab where YAML wants spaces");
  EXPECT_EQ(Refusal("a: 1\n...\nb: 2\n"), "more than one YAML document (text after the end of the first) at f.yaml:3");
  EXPECT_EQ(Refusal("a: 1\n...\nb: 2\n", IndexRules()), "f.yaml:3: more than one YAML document");
  // A tab separating a value is fine.
  EXPECT_TRUE(ParseYamlText("a:\t1\nb: [1,\t2]\n", "f.yaml").ok());
}

TEST(YamlReader, UnicodeLineBreaksAreRefusedAndEscapesAreUtf8) {
  EXPECT_EQ(Refusal("a: 1\nb: x\xE2\x80\xA8y\n"), "a line separator U+2028 at f.yaml:2: YAML would read it as a line "
                                                  "break that editors do not show; end lines with LF");
  EXPECT_EQ(Refusal("a: \"\xE2\x80\xA9\"\n"), "a paragraph separator U+2029 at f.yaml:1: YAML would read it as a line "
                                               "break that editors do not show; end lines with LF");
  EXPECT_NE(Refusal("a: \xC2\x85\n").find("control character U+0085 at f.yaml:1"), std::string::npos);
  Result<YamlDocument> doc = ParseYamlText("a: \"\\_\\N\\u00e9\"\n", "f.yaml");
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  EXPECT_EQ(doc->root.Find("a")->scalar, "\xC2\xA0\xC2\x85\xC3\xA9");
}

TEST(YamlReader, OpenCvFirstLineIsAComment) {
  Result<YamlDocument> doc = ParseYamlText("%YAML:1.0\n---\nx: 1\n", "f.yaml");
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  EXPECT_EQ(doc->root.key_lines, (std::vector<int>{3}));
  EXPECT_NE(Refusal("%FOO bar\n---\nx: 1\n").find("malformed YAML at f.yaml:1"), std::string::npos);
}

// OpenCV camera files are checked by this reader (depth, duplicate keys) before OpenCV reads them: their
// `!!opencv-matrix` tags are accepted when the rules say so, other tags still refused.
TEST(YamlReader, TagsWithTheAcceptedPrefixPass) {
  const std::string text = "%YAML:1.0\n---\nk: !!opencv-matrix\n  rows: 1\n";
  EXPECT_NE(Refusal(text).find("explicit YAML tags (tag:yaml.org,2002:opencv-matrix) are not supported"), std::string::npos);
  YamlRules rules;
  rules.accepted_tag_prefix = "tag:yaml.org,2002:opencv-";
  EXPECT_TRUE(ParseYamlText(text, "f.yaml", rules).ok());
  EXPECT_FALSE(ParseYamlText("k: !!binary x\n", "f.yaml", rules).ok());
  EXPECT_EQ(ParseYamlText(text + "k: 2\n", "f.yaml", rules).status().message(), "duplicate key `k` at f.yaml:5");
}

TEST(YamlReader, SequenceIndexRefusalsSayWhereFirst) {
  EXPECT_EQ(Refusal("a: 1\nb: &x 2\n", IndexRules()), "f.yaml:2: YAML anchors are not allowed in a sequence index");
  EXPECT_EQ(Refusal("a: *x\n", IndexRules()), "f.yaml:1: YAML aliases are not allowed in a sequence index");
  EXPECT_EQ(Refusal("a: 1\na: 2\n", IndexRules()), "f.yaml:2: duplicate key `a`");
  EXPECT_EQ(Refusal("a: [[[[[[[[[[]]]]]]]]]]\n", IndexRules()), "f.yaml:1: YAML nested deeper than 8 levels");
  EXPECT_EQ(Refusal("a:\n- - - 1\n", IndexRules(2)), "f.yaml:2: YAML nested deeper than 2 levels");
  EXPECT_EQ(Refusal("a: 1\nb: \x89PNG\n", IndexRules()), "f.yaml:2: invalid byte 0x89 (binary or corrupted file?)");
  EXPECT_EQ(Refusal("a: b\x01\n", IndexRules()), "f.yaml:1: invalid byte 0x01 (binary or corrupted file?)");
  EXPECT_EQ(Refusal("a: 1\n---\nb: 2\n", IndexRules()), "f.yaml:2: more than one YAML document");
  EXPECT_EQ(Refusal("? [a]\n: 1\n", IndexRules()), "f.yaml:1: map keys must be plain strings");
  EXPECT_EQ(Refusal("a: !!binary aGk=\n", IndexRules()), "f.yaml:1: explicit YAML tags (tag:yaml.org,2002:binary) are not allowed");
}

TEST(YamlReader, NodeLimitCountsEveryNode) {
  YamlRules rules;
  rules.max_nodes = 4;  // the map, two keys, one value
  EXPECT_TRUE(ParseYamlText("a: 1\n", "f.yaml", rules).ok());
  EXPECT_EQ(Refusal("a: 1\nb: 2\n", rules), "more than 4 YAML nodes at f.yaml:2");
}

TEST(YamlReader, LoadYamlFileNamesThePath) {
  selfcal::testing::TempDir dir("selfcal_yaml_test");
  const std::string path = dir.File("x.yaml");
  selfcal::testing::WriteFile(path, "a: 1\n");
  Result<YamlDocument> doc = LoadYamlFile(path);
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  EXPECT_EQ(doc->path, path);
  const Result<YamlDocument> absent = LoadYamlFile(dir.File("absent.yaml"));
  ASSERT_FALSE(absent.ok());
  EXPECT_NE(absent.status().message().find(dir.File("absent.yaml")), std::string::npos);
}

}  // namespace
}  // namespace selfcal::yaml
