// The strict YAML layer: schema checks (C1-C3) and malformed files (C8).
#include <sys/stat.h>

#include <cstring>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "yaml/yaml_reader.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath

// A refusal must be a Status with the config exit code that names the file (and, when given, says why).
::testing::AssertionResult CleanRefusal(const Status& status, const std::string& path, const std::string& why = "") {
  if (status.ok()) return ::testing::AssertionFailure() << "accepted";
  if (status.code() != ErrorCode::kInvalidInput) return ::testing::AssertionFailure() << "code " << status.ToString();
  if (status.message().find(path) == std::string::npos) {
    return ::testing::AssertionFailure() << "message does not name " << path << ": " << status.message();
  }
  if (!why.empty() && status.message().find(why) == std::string::npos) {
    return ::testing::AssertionFailure() << "message lacks \"" << why << "\": " << status.message();
  }
  return ::testing::AssertionSuccess();
}

std::string PumaText() { return ReadFile(SourcePath("config/robots/puma560.yaml")); }

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

Status LoadRobotText(const TempDir& dir, const std::string& text, std::string* path) {
  *path = dir.File("robot.yaml");
  WriteFile(*path, text);
  return LoadRobotModel(*path).status();
}

TEST(YamlSchema, C1UnknownKeyNamesLineAndSuggestsTheClosestKey) {
  TempDir dir;
  const std::string path = dir.File("motion.yaml");
  WriteFile(path, "speed_scale: 0.1\n# the typo is on line 3\nmax_velocty: 0.5\n");
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  Problems problems(path);
  {
    MapReader map(doc->root, "", &problems);
    double scale = 0, velocity = 0;
    EXPECT_TRUE(map.Double("speed_scale", Range::Positive(1), &scale));
    EXPECT_TRUE(map.OptionalDouble("max_velocity", Range::Positive(10), &velocity));
    map.Finish();
  }
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems.messages()[0], "unknown key `max_velocty` at " + path + ":3; did you mean `max_velocity`?");
  EXPECT_EQ(problems.ToStatus("motion limits").code(), ErrorCode::kInvalidInput);
}

TEST(YamlSchema, C1UnknownKeyInARobotJointRow) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  const std::string text = Replace(PumaText(), "d_mm: 431.8,  theta_offset_deg", "d_mm: 431.8,  theta_ofset_deg");
  const Status status = LoadRobotText(dir, text, &path);
  EXPECT_TRUE(CleanRefusal(status, path, "unknown key `theta_ofset_deg` in `joints[3]` at " + path + ":16; did you mean `theta_offset_deg`?"));
}

TEST(YamlSchema, C1UnknownKeyWithoutCloseMatchListsTheAllowedKeys) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  const Status status = LoadRobotText(dir, PumaText() + "payload_kg: 3\n", &path);
  EXPECT_TRUE(CleanRefusal(status, path, "unknown key `payload_kg` at " + path + ":22; allowed keys here:"));
}

TEST(YamlSchema, C2AllMissingKeysAreListedTogether) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  std::string text = PumaText();
  text = Replace(text, "name: puma560\n", "");
  text = Replace(text, "dh_convention: standard\n", "");
  text = Replace(text, "flange_from_cam: {xyz_mm: [40, 0, 60], rpy_deg: [0, 0, 90]}\n", "");
  text = Replace(text, "{a_mm: 20.3,  alpha_deg: -90.0, d_mm: 150.05,", "{alpha_deg: -90.0,");
  const Status status = LoadRobotText(dir, text, &path);
  EXPECT_TRUE(CleanRefusal(status, path, "missing required keys `name`, `dh_convention`, `flange_from_cam` in the document"));
  EXPECT_TRUE(CleanRefusal(status, path, "missing required keys `a_mm` (or `a_m`), `d_mm` (or `d_m`) in `joints[2]`"));
}

TEST(YamlSchema, C3NonFiniteWrongTypeAndOutOfRangeValuesAreRefused) {
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {"a_mm: 431.8,", "a_mm: .nan,", "`joints[1].a_mm` = `.nan` at "},
      {"a_mm: 431.8,", "a_mm: .inf,", "is not finite"},
      {"a_mm: 431.8,", "a_mm: -.Inf,", "is not finite"},
      {"a_mm: 431.8,", "a_mm: 1e999,", "is not finite"},
      {"a_mm: 431.8,", "a_mm: abc,", "`joints[1].a_mm` = `abc` at "},
      {"a_mm: 431.8,", "a_mm: \"431.8\",", "is not a number (found a quoted string)"},
      {"a_mm: 431.8,", "a_mm: [431.8],", "is not a number (found a sequence)"},
      {"a_mm: 431.8,", "a_mm: 0x1AF,", "is not a number"},
      {"a_mm: 431.8,", "a_mm: 43180000,", "is out of range: must be in [-10000, 10000]"},
      {"alpha_deg: 0.0,   d_mm: 0.0,    theta_offset_deg: 0.0, min_deg: -45", "alpha_deg: 900,   d_mm: 0.0,    theta_offset_deg: 0.0, min_deg: -45", "must be in [-360, 360]"},
      {"min_deg: -225, max_deg: 45}", "min_deg: 45, max_deg: -225}", "is not below max"},
      {"min_deg: -266, max_deg: 266}", "min_deg: -266, max_deg: 9000}", "`joints[5].max_deg` = `9000`"},
      {"dh_convention: standard", "dh_convention: craig", "must be one of standard, modified, modified_hayati"},
      {"rpy_deg: [0, 0, 90]}", "rpy_deg: [0, 90]}", "has 2 values, expected 3"},
      {"xyz_mm: [40, 0, 60]", "xyz_mm: [40, 0, .nan]", "`flange_from_cam.xyz_mm[2]` = `.nan`"},
  };
  TempDir dir;
  for (const Case& c : cases) {
    std::string path = dir.File("robot.yaml");
    const Status status = LoadRobotText(dir, Replace(PumaText(), c.from, c.to), &path);
    EXPECT_TRUE(CleanRefusal(status, path, c.expected)) << c.to;
  }
}

TEST(YamlSchema, C3BothUnitsOfOneQuantityAreRefused) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  const Status status = LoadRobotText(dir, Replace(PumaText(), "a_mm: 431.8,", "a_mm: 431.8, a_m: 0.4318,"), &path);
  EXPECT_TRUE(CleanRefusal(status, path, "`joints[1].a_mm` and `joints[1].a_m`"));
}

TEST(YamlSchema, NumbersRoundTripExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-1e3, 1e3);
  TempDir dir;
  for (int i = 0; i < 2000; ++i) {
    double value = uniform(rng);
    if (i % 3 == 0) value *= 1e-9;
    if (i % 5 == 0) value *= 1e12;
    if (i == 0) value = -0.0;
    Result<yaml::YamlDocument> doc = yaml::ParseYamlText("v: " + YamlNumber(value) + "\n", "number.yaml");
    ASSERT_TRUE(doc.ok());
    Problems problems("number.yaml");
    MapReader map(doc->root, "", &problems);
    double read = 1;
    ASSERT_TRUE(map.Double("v", Range(), &read)) << YamlNumber(value);
    EXPECT_EQ(std::memcmp(&read, &value, sizeof(double)), 0) << YamlNumber(value);
  }
  EXPECT_EQ(YamlNumber(1e-5), "1.0e-05");  // a float for YAML 1.1 readers too
  EXPECT_EQ(YamlNumber(0.04), "0.04");
}

TEST(YamlSchema, EditDistanceCountsTranspositionsOnce) {
  EXPECT_EQ(EditDistance("max_velocty", "max_velocity"), 1);
  EXPECT_EQ(EditDistance("fx_xp", "fx_px"), 1);
  EXPECT_EQ(EditDistance("", "abc"), 3);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
}

// ---- C8: malformed files. Every case is a clean kInvalidInput Status naming the file. ----

TEST(MalformedFiles, C8EmptyAndCommentOnlyFiles) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "", &path), path, "is empty"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "# nothing here\n\n", &path), path, "is empty"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "just a string\n", &path), path, "must be a map"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "- 1\n- 2\n", &path), path, "must be a map"));
}

TEST(MalformedFiles, C8EveryTruncationOfAValidFileIsRefusedCleanly) {
  TempDir dir;
  const std::string text = PumaText();
  for (size_t length = 0; length + 1 < text.size(); length += 7) {
    std::string path = dir.File("robot.yaml");
    const Status status = LoadRobotText(dir, text.substr(0, length), &path);
    EXPECT_TRUE(CleanRefusal(status, path)) << "length " << length;
  }
}

TEST(MalformedFiles, C8BinaryGarbage) {
  TempDir dir;
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    std::string garbage(1 + rng() % 4096, '\0');
    for (char& c : garbage) c = static_cast<char>(rng());
    std::string path = dir.File("robot.yaml");
    EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, garbage, &path), path)) << trial;
  }
  std::string path = dir.File("robot.yaml");
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, std::string("name: a\0b\n", 10), &path), path, "control character U+0000"));
}

TEST(MalformedFiles, C8PrintableGarbageNeverCrashes) {
  TempDir dir;
  std::mt19937 rng(2);
  const std::string alphabet = "abc:-[]{}\"'&*!|>#?,.0123 \n\t%@`";
  for (int trial = 0; trial < 300; ++trial) {
    std::string text(rng() % 200, ' ');
    for (char& c : text) c = alphabet[rng() % alphabet.size()];
    std::string path = dir.File("robot.yaml");
    EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, text, &path), path)) << text;
  }
}

TEST(MalformedFiles, C8InvalidUtf8NamesTheLine) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  const std::string text = Replace(PumaText(), "name: puma560", "name: puma\xC3\x28" "560");
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, text, &path), path, "invalid UTF-8 (byte 0xC3) at " + path + ":8"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "name: \xED\xA0\x80\n", &path), path, "invalid UTF-8"));  // surrogate
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "name: \xC0\xAF\n", &path), path, "invalid UTF-8"));      // overlong
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "\xFF\xFEn\0a\0", &path), path, "UTF-16"));
}

TEST(MalformedFiles, C8FileOverTheSizeCapIsRefusedBeforeParsing) {
  TempDir dir;
  const std::string path = dir.File("big.yaml");
  // 11 MB of one valid-looking sequence: refused by size, not parsed.
  std::string text = "poses_deg:\n";
  while (text.size() < 11u * 1000u * 1000u) text += "  - [0, 0, 0, 0, 0, 0]\n";
  WriteFile(path, text);
  const std::string size = std::to_string(text.size()) + " bytes, more than the limit of 10485760 bytes";
  EXPECT_TRUE(CleanRefusal(LoadRobotModel(path).status(), path, path + " is " + size));
  EXPECT_TRUE(CleanRefusal(yaml::ParseYamlText(text, "memory.yaml").status(), "memory.yaml", "memory.yaml is " + size));
}

TEST(MalformedFiles, C8DeepNestingIsRefusedWithoutRecursion) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  const int deep = 10000;
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "a: " + std::string(deep, '[') + std::string(deep, ']') + "\n", &path),
                           path, "nested deeper than 64 levels"));
  std::string flow_maps = "a: ";
  for (int i = 0; i < deep; ++i) flow_maps += "{b: ";
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, flow_maps + "1" + std::string(deep, '}'), &path), path, "nested deeper"));
  // Block sequences nest through "- - - ...": the tree builder refuses them at the limit, as it does flow
  // collections.
  std::string block = "a:\n  ";
  for (int i = 0; i < deep; ++i) block += "- ";
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, block + "1\n", &path), path, "nested deeper than 64 levels"));
  // 64 levels are fine for the parser (the schema then refuses the content).
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "a: " + std::string(63, '[') + std::string(63, ']') + "\n", &path),
                           path, "unknown key `a`"));
}

TEST(MalformedFiles, C8AliasBombAndAnchorsAreRefused) {
  TempDir dir;
  std::string bomb = "a: &a [\"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\"]\n";
  for (char c = 'b'; c <= 'j'; ++c) {
    bomb += std::string(1, c) + ": &" + c + " [";
    for (int i = 0; i < 9; ++i) bomb += std::string(i ? ", " : "") + "*" + static_cast<char>(c - 1);
    bomb += "]\n";
  }
  std::string path = dir.File("robot.yaml");
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, bomb, &path), path, "anchors (&name) are not supported"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "a: *x\n", &path), path));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "a: !!binary aGVsbG8=\n", &path), path, "explicit YAML tags"));
}

TEST(MalformedFiles, C8DuplicateKeysAndSecondDocumentsAreRefused) {
  TempDir dir;
  std::string path = dir.File("robot.yaml");
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, PumaText() + "name: other\n", &path), path,
                           "duplicate key `name` at " + path + ":22"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, PumaText() + "---\nname: other\n", &path), path, "more than one YAML document"));
  EXPECT_TRUE(CleanRefusal(LoadRobotText(dir, "? [a, b]\n: 1\n", &path), path, "map keys must be plain strings"));
}

TEST(MalformedFiles, C8BomAndCrlfAreAccepted) {
  TempDir dir;
  std::string crlf = "\xEF\xBB\xBF";
  for (char c : PumaText()) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const std::string path = dir.File("bom_crlf.yaml");
  WriteFile(path, crlf);
  Result<RobotModel> with_bom = LoadRobotModel(path);
  ASSERT_TRUE(with_bom.ok()) << with_bom.status().ToString();
  Result<RobotModel> plain = LoadRobotModel(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(plain.ok());
  ASSERT_EQ(with_bom->num_joints(), plain->num_joints());
  for (int i = 0; i < plain->num_joints(); ++i) EXPECT_EQ(with_bom->links[i].d, plain->links[i].d);
  // Line numbers still count CRLF lines once.
  std::string bad = crlf;
  bad.replace(bad.find("a_mm: 431.8"), 11, "a_mm: .nan ");
  WriteFile(path, bad);
  EXPECT_TRUE(CleanRefusal(LoadRobotModel(path).status(), path, "`.nan` at " + path + ":14"));
}

TEST(MalformedFiles, C8MissingFileDirectoryAndFifoAreRefused) {
  TempDir dir;
  EXPECT_TRUE(CleanRefusal(LoadRobotModel(dir.File("absent.yaml")).status(), dir.File("absent.yaml"), "cannot open"));
  EXPECT_TRUE(CleanRefusal(LoadRobotModel(dir.path()).status(), dir.path(), "not a regular file"));
  const std::string fifo = dir.File("fifo.yaml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_TRUE(CleanRefusal(LoadRobotModel(fifo).status(), fifo, "not a regular file"));
}

}  // namespace
}  // namespace selfcal::io
