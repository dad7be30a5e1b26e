#include "session/session_dir.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <functional>

#include <gtest/gtest.h>

#include "base/sha256.h"
#include "session/session_test_util.h"

namespace selfcal::session {
namespace {

using testing::Contains;
using testing::CreateTestSession;
using testing::ReadFile;
using testing::TempDir;
using testing::TestCreateOptions;
using testing::TestInputs;
using testing::WriteFile;

bool Exists(const std::string& path) { return std::filesystem::exists(path); }

unsigned Permissions(const std::string& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return info.st_mode & 07777;
}

TEST(SessionDirTest, SessionIdIsDerivedFromTimeAndPath) {
  const std::string id = DeriveSessionId("/data/sessions/a", "2025-03-01T12:00:00.250Z");
  EXPECT_EQ(id, "20250301T120000250Z-" + Sha256Hex("/data/sessions/a").substr(0, 8));
  EXPECT_EQ(DeriveSessionId("/data/sessions/./a/", "2025-03-01T12:00:00.250Z").substr(0, 20), id.substr(0, 20));
  EXPECT_NE(DeriveSessionId("/data/sessions/b", "2025-03-01T12:00:00.250Z"), id);
}

TEST(SessionDirTest, CreateWritesTheDocumentedLayout) {
  TempDir dir;
  const std::string path = dir.File("session");
  Result<Session> session = CreateTestSession(path);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->path(), path);
  EXPECT_EQ(dir.List("session"), (std::vector<std::string>{"images", "inputs", "journal.log", "lock", "session.json"}));
  EXPECT_EQ(dir.List("session/inputs"), (std::vector<std::string>{"config.yaml", "plan.yaml", "robot.yaml"}));
  EXPECT_TRUE(dir.List("session/images").empty());
  EXPECT_EQ(ReadFile(path + "/journal.log"), "");
  EXPECT_EQ(ReadFile(path + "/inputs/robot.yaml"), "name: puma560\n");
  EXPECT_EQ(Permissions(path + "/inputs/robot.yaml"), 0444u);
  EXPECT_TRUE(Contains(ReadFile(path + "/lock"), std::to_string(::getpid()) + " "));

  const nlohmann::json manifest = nlohmann::json::parse(ReadFile(path + "/session.json"));
  EXPECT_EQ(manifest["format"], "selfcal-session");
  EXPECT_EQ(manifest["version"], 1);
  EXPECT_EQ(manifest["session_id"], DeriveSessionId(path, "2025-03-01T12:00:00Z"));
  EXPECT_EQ(manifest["created_utc"], "2025-03-01T12:00:00Z");
  EXPECT_EQ(manifest["software_version"], "selfcal 0.1.0-test");
  ASSERT_EQ(manifest["inputs"].size(), 3u);
  EXPECT_EQ(manifest["inputs"][1]["name"], "robot.yaml");
  EXPECT_EQ(manifest["inputs"][1]["bytes"], 14);
  EXPECT_EQ(manifest["inputs"][1]["sha256"], Sha256Hex("name: puma560\n"));

  // The manifest reads back as written, and the stored inputs with it.
  Result<SessionManifest> read = ReadManifest(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->session_id, session->manifest().session_id);
  ASSERT_NE(read->FindInput("plan.yaml"), nullptr);
  EXPECT_EQ(read->FindInput("plan.yaml")->sha256_hex, Sha256Hex("poses: []\n"));
  EXPECT_EQ(session->ReadInput("config.yaml").value(), "mode: simulated\n");
  EXPECT_FALSE(session->ReadInput("camera.yaml").ok());
}

TEST(SessionDirTest, GivenSessionIdIsUsed) {
  TempDir dir;
  CreateOptions options = TestCreateOptions();
  options.session_id = "bench-7";
  Result<Session> session = CreateSession(dir.File("s"), TestInputs(), "v", options);
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  EXPECT_EQ(session->manifest().session_id, "bench-7");
}

TEST(SessionDirTest, CreateRefusesANonEmptyDirectory) {
  TempDir dir;
  const std::string path = dir.File("session");
  ASSERT_TRUE(std::filesystem::create_directory(path));
  WriteFile(path + "/notes.txt", "keep me");
  Result<Session> session = CreateSession(path, TestInputs(), "v", TestCreateOptions());
  ASSERT_FALSE(session.ok());
  EXPECT_EQ(session.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(session.status().message(), path)) << session.status().message();
  EXPECT_TRUE(Contains(session.status().message(), "never overwritten")) << session.status().message();
  EXPECT_EQ(dir.List("session"), std::vector<std::string>{"notes.txt"});
  EXPECT_EQ(ReadFile(path + "/notes.txt"), "keep me");

  // An existing session is not empty either.
  ASSERT_TRUE(CreateTestSession(dir.File("first")).ok());
  EXPECT_FALSE(CreateSession(dir.File("first"), TestInputs(), "v", TestCreateOptions()).ok());
}

TEST(SessionDirTest, CreateUsesAnEmptyExistingDirectory) {
  TempDir dir;
  ASSERT_TRUE(std::filesystem::create_directory(dir.File("empty")));
  EXPECT_TRUE(CreateTestSession(dir.File("empty") + "/").ok());
  EXPECT_TRUE(Exists(dir.File("empty/session.json")));
}

TEST(SessionDirTest, CreateRefusesBadArgumentsBeforeWritingAnything) {
  TempDir dir;
  const std::string path = dir.File("s");
  struct Case {
    SessionInputs inputs;
    std::string created_utc;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{{"config.yaml", "a"}, {"config.yaml", "b"}}, "2025-03-01T12:00:00Z", "given twice"},
      {{{"../config.yaml", "a"}}, "2025-03-01T12:00:00Z", "not a plain file name"},
      {{{".hidden", "a"}}, "2025-03-01T12:00:00Z", "not a plain file name"},
      {TestInputs(), "2025-03-01 12:00:00", "not UTC ISO 8601"},
      {TestInputs(), "2025-13-01T12:00:00Z", "not UTC ISO 8601"},
  };
  for (const Case& c : cases) {
    CreateOptions options = TestCreateOptions();
    options.created_utc = c.created_utc;
    Result<Session> session = CreateSession(path, c.inputs, "v", options);
    ASSERT_FALSE(session.ok()) << c.expected;
    EXPECT_EQ(session.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(session.status().message(), c.expected)) << session.status().message();
    EXPECT_FALSE(Exists(path));
  }
  Result<Session> no_parent = CreateSession(dir.File("no/such/s"), TestInputs(), "v", TestCreateOptions());
  ASSERT_FALSE(no_parent.ok());
  EXPECT_TRUE(Contains(no_parent.status().message(), "does not exist")) << no_parent.status().message();
}

TEST(SessionDirTest, CreateChecksFreeSpace) {
  TempDir dir;
  CreateOptions options = TestCreateOptions();
  options.min_free_bytes = std::uint64_t{1} << 62;  // 4 EiB
  Result<Session> session = CreateSession(dir.File("s"), TestInputs(), "v", options);
  ASSERT_FALSE(session.ok());
  EXPECT_EQ(session.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(session.status().message(), "bytes are free")) << session.status().message();
  EXPECT_FALSE(Exists(dir.File("s")));
}

TEST(SessionDirTest, CreateRefusesAReadOnlyDirectory) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only directories";
  TempDir dir;
  const std::string parent = dir.File("ro");
  ASSERT_TRUE(std::filesystem::create_directory(parent));
  ASSERT_EQ(::chmod(parent.c_str(), 0555), 0);
  Result<Session> session = CreateSession(parent + "/s", TestInputs(), "v", TestCreateOptions());
  ::chmod(parent.c_str(), 0755);
  ASSERT_FALSE(session.ok());
  EXPECT_TRUE(Contains(session.status().message(), "not writable")) << session.status().message();
}

TEST(SessionDirTest, LockRefusesASecondSessionAndIsReleasedOnDestruction) {
  TempDir dir;
  const std::string path = dir.File("s");
  {
    Result<Session> first = CreateTestSession(path);
    ASSERT_TRUE(first.ok());
    Result<Session> second = OpenSession(path, TestInputs(), false);
    ASSERT_FALSE(second.ok());
    EXPECT_EQ(second.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(second.status().message(),
                         "session " + path + " is in use by pid " + std::to_string(::getpid()) + " on host "))
        << second.status().message();
    // The refused attempt left the holder's line in place.
    EXPECT_TRUE(Contains(ReadFile(path + "/lock"), std::to_string(::getpid())));
    // A moved session keeps its lock.
    Session moved = std::move(first).value();
    EXPECT_FALSE(OpenSession(path, TestInputs(), false).ok());
  }
  EXPECT_EQ(ReadFile(path + "/lock"), "");  // released cleanly
  Result<Session> again = OpenSession(path, TestInputs(), false);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->open_report().stale_lock_from, "");
}

// P6 (issue 16): a stale lock is taken over only when the operator confirms it; refused, it is left as it was.
TEST(SessionDirTest, AStaleLockIsTakenOverOnlyWhenConfirmedAndReported) {
  TempDir dir;
  const std::string path = dir.File("s");
  ASSERT_TRUE(CreateTestSession(path).ok());
  WriteFile(path + "/lock", "4242 deadhost 2025-03-01T11:00:00Z\n");  // left by a process that died
  const Result<Session> refused = OpenSession(path, TestInputs(), false);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(refused.status().message(), "its lock was left by pid 4242 on host deadhost (since "
                                                   "2025-03-01T11:00:00Z)"))
      << refused.status().message();
  EXPECT_TRUE(Contains(refused.status().message(), "--take-over-stale-lock")) << refused.status().message();
  EXPECT_EQ(ReadFile(path + "/lock"), "4242 deadhost 2025-03-01T11:00:00Z\n");
  Result<Session> session = OpenSession(path, TestInputs(), false, JournalLimits(), /*take_over_stale_lock=*/true);
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  EXPECT_EQ(session->open_report().stale_lock_from, "4242 deadhost 2025-03-01T11:00:00Z");
  EXPECT_TRUE(Contains(ReadFile(path + "/lock"), std::to_string(::getpid()) + " "));
}

TEST(SessionDirTest, ResumeWithChangedInputsIsRefusedUnlessAllowed) {
  TempDir dir;
  const std::string path = dir.File("s");
  ASSERT_TRUE(CreateTestSession(path).ok());
  SessionInputs changed = TestInputs();
  changed[0].contents = "mode: real\n";             // config.yaml differs
  changed.push_back({"camera.yaml", "fx: 800\n"});  // not recorded
  Result<Session> refused = OpenSession(path, changed, false);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kInvalidInput);
  const std::string& message = refused.status().message();
  EXPECT_TRUE(Contains(message, "config.yaml (recorded 16 bytes")) << message;
  EXPECT_TRUE(Contains(message, "camera.yaml (not recorded")) << message;
  EXPECT_FALSE(Contains(message, "robot.yaml")) << message;
  EXPECT_FALSE(Contains(message, "plan.yaml")) << message;
  EXPECT_EQ(ReadFile(path + "/lock"), "");  // refused before locking

  Result<Session> allowed = OpenSession(path, changed, true);
  ASSERT_TRUE(allowed.ok()) << allowed.status().ToString();
  ASSERT_EQ(allowed->open_report().changed_inputs.size(), 2u);
  EXPECT_TRUE(Contains(allowed->open_report().changed_inputs[0], "config.yaml"));
  // The recorded inputs stay as they were.
  EXPECT_EQ(allowed->ReadInput("config.yaml").value(), "mode: simulated\n");
}

TEST(SessionDirTest, AModifiedStoredInputIsDetected) {
  TempDir dir;
  const std::string path = dir.File("s");
  ASSERT_TRUE(CreateTestSession(path).ok());
  ASSERT_EQ(::chmod((path + "/inputs/plan.yaml").c_str(), 0644), 0);
  WriteFile(path + "/inputs/plan.yaml", "poses: [[1]]\n");
  Result<Session> session = OpenSession(path, {}, false);
  ASSERT_TRUE(session.ok());
  Result<std::string> plan = session->ReadInput("plan.yaml");
  ASSERT_FALSE(plan.ok());
  EXPECT_TRUE(Contains(plan.status().message(), "modified")) << plan.status().message();
}

TEST(SessionDirTest, TheManifestIsReadStrictly) {
  TempDir dir;
  const std::string path = dir.File("s");
  ASSERT_TRUE(CreateTestSession(path).ok());
  const nlohmann::json good = nlohmann::json::parse(ReadFile(path + "/session.json"));
  // Issue 16: each refusal names the line too, of the key it is about (a missing key: of its object).
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    std::string expected;
    std::string line_of;  // the text on the line the refusal names
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json& j) { j["version"] = 2; }, "unknown major version 2", "\"version\": 2"},
      {[](nlohmann::json& j) { j["format"] = "other"; }, "\"format\" is not \"selfcal-session\": not a selfcal session",
       "\"format\": \"other\""},
      {[](nlohmann::json& j) { j["extra"] = 1; }, "unknown key \"extra\"", "\"extra\": 1"},
      {[](nlohmann::json& j) { j.erase("created_utc"); }, "missing key \"created_utc\"", "{"},
      {[](nlohmann::json& j) { j["inputs"][0]["sha256"] = "ABC"; }, "inputs[0]: \"sha256\" must be 64",
       "\"sha256\": \"ABC\""},
      {[](nlohmann::json& j) { j["inputs"][1]["bytes"] = -1; }, "inputs[1]: \"bytes\"", "\"bytes\": -1"},
      {[](nlohmann::json& j) { j["session_id"] = 7; }, "\"session_id\" must be a string", "\"session_id\": 7"},
  };
  for (const Case& c : cases) {
    nlohmann::json edited = good;
    c.edit(edited);
    const std::string text = edited.dump(2);
    WriteFile(path + "/session.json", text);
    Result<Session> session = OpenSession(path, {}, false);
    ASSERT_FALSE(session.ok()) << c.expected;
    EXPECT_EQ(session.status().code(), ErrorCode::kInvalidInput);
    const size_t at = text.find(c.line_of);
    ASSERT_NE(at, std::string::npos) << c.line_of;
    const std::string line = std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
    EXPECT_TRUE(Contains(session.status().message(), path + "/session.json:" + line + ": " + c.expected))
        << "line " << line << ": " << session.status().message();
  }
  WriteFile(path + "/session.json", good.dump(2));
  std::filesystem::rename(path + "/journal.log", path + "/journal.log.moved");
  Result<Session> no_journal = OpenSession(path, {}, false);
  ASSERT_FALSE(no_journal.ok());
  EXPECT_TRUE(Contains(no_journal.status().message(), "has no journal.log")) << no_journal.status().message();
  EXPECT_FALSE(Exists(path + "/journal.log"));  // not started afresh
  WriteFile(path + "/session.json", "{\n  \"format\": \"selfcal-session\",\n  not json\n}\n");
  Result<Session> not_json = OpenSession(path, {}, false);
  ASSERT_FALSE(not_json.ok());
  EXPECT_TRUE(Contains(not_json.status().message(), path + "/session.json:3: not JSON: syntax error"))
      << not_json.status().message();
  std::filesystem::remove(path + "/session.json");
  Result<Session> missing = OpenSession(path, {}, false);
  ASSERT_FALSE(missing.ok());
  // The rest of a session without its manifest reads as an interrupted creation, named with its remedies.
  EXPECT_TRUE(Contains(missing.status().message(), "creation was interrupted")) << missing.status().message();
  EXPECT_TRUE(Contains(missing.status().message(), "selfcal session discard")) << missing.status().message();
}

TEST(SessionDirTest, UnreferencedImagesAreMovedToOrphans) {
  TempDir dir;
  const std::string path = dir.File("s");
  {
    Result<Session> session = CreateTestSession(path);
    ASSERT_TRUE(session.ok());
    ASSERT_TRUE(session.value().WriteImage("p00.png", "image zero").ok());
    ASSERT_TRUE(session.value().journal().Append({{"type", "frame_written"}, {"image", "images/p00.png"}}).ok());
    ASSERT_TRUE(session.value().WriteImage("p01.png", "image one, never journaled").ok());
  }
  WriteFile(path + "/images/.p02.png.tmp.Ab12Cd", "half an image");  // a crash inside WriteImage
  {
    Result<Session> session = OpenSession(path, TestInputs(), false);
    ASSERT_TRUE(session.ok()) << session.status().ToString();
    EXPECT_EQ(session->open_report().orphans,
              (std::vector<std::string>{"orphans/.p02.png.tmp.Ab12Cd", "orphans/p01.png"}));
    EXPECT_EQ(dir.List("s/images"), std::vector<std::string>{"p00.png"});
    EXPECT_EQ(ReadFile(path + "/orphans/p01.png"), "image one, never journaled");
    EXPECT_EQ(ReadFile(path + "/orphans/.p02.png.tmp.Ab12Cd"), "half an image");
    // The name is free again; an orphan of the same name later does not replace the first.
    ASSERT_TRUE(session.value().WriteImage("p01.png", "second try").ok());
  }
  Result<Session> reopened = OpenSession(path, TestInputs(), false);
  ASSERT_TRUE(reopened.ok());
  EXPECT_EQ(reopened->open_report().orphans, std::vector<std::string>{"orphans/p01.png.1"});
  EXPECT_EQ(ReadFile(path + "/orphans/p01.png"), "image one, never journaled");
  EXPECT_EQ(ReadFile(path + "/orphans/p01.png.1"), "second try");
}

TEST(SessionDirTest, WriteImageIsAtomicAndNeverReplaces) {
  TempDir dir;
  const std::string path = dir.File("s");
  Result<Session> session = CreateTestSession(path);
  ASSERT_TRUE(session.ok());
  ASSERT_TRUE(session.value().WriteImage("f.png", "AAAA").ok());
  EXPECT_EQ(ReadFile(path + "/images/f.png"), "AAAA");
  EXPECT_TRUE(session.value().WriteImage("f.png", "AAAA").ok());  // identical retry
  const Status replaced = session.value().WriteImage("f.png", "BBBB");
  EXPECT_EQ(replaced.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(replaced.message(), "never overwritten")) << replaced.message();
  EXPECT_EQ(ReadFile(path + "/images/f.png"), "AAAA");
  EXPECT_FALSE(session.value().WriteImage("f.png", "AAAAA").ok());  // a longer file is not identical
  for (const char* bad : {"", ".hidden", "../escape.png", "a/b.png"}) {
    EXPECT_EQ(session.value().WriteImage(bad, "x").code(), ErrorCode::kInvalidInput) << bad;
  }
  EXPECT_EQ(dir.List("s/images"), std::vector<std::string>{"f.png"});  // no temporary file left
  EXPECT_FALSE(Exists(dir.File("escape.png")));
  EXPECT_EQ(ImageRecordPath("f.png"), "images/f.png");
}

TEST(SessionDirTest, CheckFreeSpace) {
  TempDir dir;
  Result<Session> session = CreateTestSession(dir.File("s"));
  ASSERT_TRUE(session.ok());
  EXPECT_TRUE(session->CheckFreeSpace(0).ok());
  const Status full = session->CheckFreeSpace(std::uint64_t{1} << 62);
  EXPECT_EQ(full.code(), ErrorCode::kHardware);
  EXPECT_TRUE(Contains(full.message(), dir.File("s"))) << full.message();
}

TEST(SessionDirTest, OpenRecoversATornJournalAndRefusesADamagedOne) {
  TempDir dir;
  const std::string path = dir.File("s");
  {
    Result<Session> session = CreateTestSession(path);
    ASSERT_TRUE(session.ok());
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(session.value().journal().Append({{"type", "t"}, {"i", i}}).ok());
  }
  const std::string journal = ReadFile(path + "/journal.log");
  WriteFile(path + "/journal.log", journal + "J1 0000");
  {
    Result<Session> session = OpenSession(path, {}, false);
    ASSERT_TRUE(session.ok()) << session.status().ToString();
    EXPECT_EQ(session->open_report().journal.dropped_bytes, 7u);
    EXPECT_EQ(session->journal().records().size(), 3u);
  }
  std::string damaged = journal;
  damaged[journal.find("\"i\":1")] = 'X';
  WriteFile(path + "/journal.log", damaged);
  Result<Session> refused = OpenSession(path, {}, false);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(Contains(refused.status().message(), "record 2 at byte offset")) << refused.status().message();
  EXPECT_EQ(ReadFile(path + "/lock"), "");  // the refused open released the lock
}

// Issue 36: a key given twice in session.json was taken, the last value winning; refused naming the line.
TEST(SessionDirTest, AManifestKeyGivenTwiceIsRefusedNamingItsLines) {
  TempDir dir;
  const std::string text =
      ReadFile(std::string(SELFCAL_SOURCE_DIR) + "/fuzz/regressions/manifest/duplicate-key-session-id.json");
  std::filesystem::create_directories(dir.path() + "/s");
  WriteFile(dir.path() + "/s/session.json", text);
  const Result<SessionManifest> read = ReadManifest(dir.path() + "/s");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(read.status().message(), dir.path() + "/s/session.json:28: `session_id` is given twice (lines 26 and 28): "
                                                  "a JSON reader would keep one of them without a word; keep one");
}

}  // namespace
}  // namespace selfcal::session
