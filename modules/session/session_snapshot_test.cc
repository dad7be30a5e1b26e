#include "session/session_snapshot.h"

#include <sys/stat.h>

#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "base/sha256.h"
#include "session/session_observations.h"
#include "session/session_test_util.h"
#include "session/setup_file.h"

namespace selfcal::session {
namespace {

using testing::Contains;
using testing::ReadFile;
using testing::TempDir;
using testing::WriteFile;
using testing::CreateTestSession;

// Every entry under `root` (directories too) with its mode and, for files, the SHA-256 of its bytes.
std::map<std::string, std::string> TreeState(const std::string& root) {
  std::map<std::string, std::string> state;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    struct stat info {};
    ::lstat(entry.path().c_str(), &info);
    const std::string name = std::filesystem::relative(entry.path(), root).string();
    state[name] = std::to_string(info.st_mode) + " " + std::to_string(info.st_size) +
                  (entry.is_regular_file() ? " " + Sha256Hex(ReadFile(entry.path().string())) : "");
  }
  return state;
}

// A closed session with one recorded image, one unrecorded image and a torn journal tail.
std::string MakeUntidySession(const TempDir& dir) {
  const std::string path = dir.File("s");
  {
    Result<Session> session = CreateTestSession(path);
    EXPECT_TRUE(session.ok());
    EXPECT_TRUE(session.value().WriteImage("p00_0.png", "image zero").ok());
    EXPECT_TRUE(session.value().journal().Append({{"type", "frame_written"}, {"image", "images/p00_0.png"}}).ok());
    EXPECT_TRUE(session.value().WriteImage("p01_0.png", "never journaled").ok());
  }
  const std::string journal = ReadFile(path + "/journal.log");
  WriteFile(path + "/journal.log", journal + FrameJournalRecord(R"({"type":"finished","time_s":1})").substr(0, 30));
  return path;
}

TEST(SessionSnapshotTest, ReadsAnUntidySessionAndChangesNothing) {
  TempDir dir;
  const std::string path = MakeUntidySession(dir);
  const std::uint64_t journal_bytes = std::filesystem::file_size(path + "/journal.log");
  const auto before = TreeState(path);

  Result<SessionSnapshot> snapshot = ReadSession(path);
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().ToString();
  EXPECT_EQ(TreeState(path), before);  // no lock written, nothing truncated, no orphans/ made
  EXPECT_FALSE(std::filesystem::exists(path + "/orphans"));

  EXPECT_EQ(snapshot->manifest_sha256, Sha256Hex(ReadFile(path + "/session.json")));
  EXPECT_EQ(snapshot->inputs.size(), 3u);
  EXPECT_EQ(snapshot->Input("robot.yaml").value(), "name: puma560\n");
  EXPECT_FALSE(snapshot->Input("setup.json").ok());
  ASSERT_EQ(snapshot->records.size(), 1u);
  ASSERT_TRUE(snapshot->journal.truncated());
  EXPECT_EQ(snapshot->journal.dropped_bytes, 30u);
  EXPECT_EQ(snapshot->journal.valid_bytes, journal_bytes - 30);
  EXPECT_EQ(snapshot->unrecorded_images, std::vector<std::string>{"images/p01_0.png"});
  const std::vector<std::string> findings = snapshot->Findings();
  ASSERT_EQ(findings.size(), 2u);
  EXPECT_TRUE(Contains(findings[0], "torn tail of 30 bytes at byte offset " + std::to_string(journal_bytes - 30)))
      << findings[0];
  EXPECT_TRUE(Contains(findings[0], "would be truncated on resume")) << findings[0];
  EXPECT_TRUE(Contains(findings[1], path + "/images/p01_0.png")) << findings[1];
  EXPECT_TRUE(Contains(findings[1], "would be moved to orphans/ on resume")) << findings[1];

  // A resume is what repairs it.
  Result<Session> opened = OpenSession(path, {}, false);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  EXPECT_EQ(opened->open_report().journal.dropped_bytes, 30u);
  EXPECT_EQ(opened->open_report().orphans, std::vector<std::string>{"orphans/p01_0.png"});
}

TEST(SessionSnapshotTest, ReadsASessionInUseWithoutTakingItsLock) {
  TempDir dir;
  const std::string path = dir.File("s");
  Result<Session> session = CreateTestSession(path);
  ASSERT_TRUE(session.ok());
  const std::string lock = ReadFile(path + "/lock");
  Result<SessionSnapshot> snapshot = ReadSession(path);
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().ToString();
  EXPECT_TRUE(snapshot->Findings().empty());
  EXPECT_EQ(ReadFile(path + "/lock"), lock);
}

TEST(SessionSnapshotTest, EveryRecordedInputIsCheckedAgainstTheManifest) {
  TempDir dir;
  const std::string path = MakeUntidySession(dir);
  ::chmod((path + "/inputs/robot.yaml").c_str(), 0644);
  WriteFile(path + "/inputs/robot.yaml", "name: puma561\n");  // same size, other bytes
  std::filesystem::remove(path + "/inputs/plan.yaml");
  const auto before = TreeState(path);

  Result<SessionSnapshot> snapshot = ReadSession(path);
  ASSERT_FALSE(snapshot.ok());
  EXPECT_EQ(snapshot.status().code(), ErrorCode::kInvalidInput);
  const std::string& message = snapshot.status().message();
  EXPECT_TRUE(Contains(message, path + "/inputs/robot.yaml: differs from the size or SHA-256 recorded in session.json"))
      << message;
  EXPECT_TRUE(Contains(message, path + "/inputs/plan.yaml: missing")) << message;
  EXPECT_FALSE(Contains(message, "config.yaml")) << message;
  EXPECT_EQ(TreeState(path), before);
}

TEST(SessionSnapshotTest, ADamagedJournalIsRefusedAndLeftAlone) {
  TempDir dir;
  const std::string path = dir.File("s");
  {
    Result<Session> session = CreateTestSession(path);
    ASSERT_TRUE(session.ok());
    ASSERT_TRUE(session.value().journal().Append({{"type", "a"}}).ok());
    ASSERT_TRUE(session.value().journal().Append({{"type", "b"}}).ok());
  }
  std::string journal = ReadFile(path + "/journal.log");
  journal[25] ^= 0x01;  // inside the first payload: its CRC no longer matches, a valid record follows
  WriteFile(path + "/journal.log", journal);
  const auto before = TreeState(path);
  Result<SessionSnapshot> snapshot = ReadSession(path);
  ASSERT_FALSE(snapshot.ok());
  EXPECT_TRUE(Contains(snapshot.status().message(), "record 1 at byte offset 0")) << snapshot.status().message();
  EXPECT_EQ(TreeState(path), before);
}

TEST(SessionSnapshotTest, NotASessionIsRefused) {
  TempDir dir;
  std::filesystem::create_directory(dir.File("empty"));
  Result<SessionSnapshot> snapshot = ReadSession(dir.File("empty"));
  ASSERT_FALSE(snapshot.ok());
  EXPECT_TRUE(Contains(snapshot.status().message(), "is not a selfcal session")) << snapshot.status().message();
  EXPECT_FALSE(std::filesystem::exists(dir.File("empty/lock")));
}

TEST(SetupFileTest, RoundTripAndStrictness) {
  ObservationSet setup;
  setup.camera.width_px = 640;
  setup.camera.height_px = 480;
  setup.camera.fx_px = 800;
  setup.camera.cx_px = 320;
  setup.camera.cy_px = 240;
  setup.pixel_noise_px = 0.05;
  setup.yardsticks = {{0, 5, 0.1}};
  setup.check_distances = {{1, 2, 0.02}, {3, 4, 0.03}};
  ObservationSet read;
  ASSERT_TRUE(ParseSetupFile(SetupFileText(setup), "setup.json", &read).ok());
  EXPECT_EQ(read.camera.width_px, 640);
  EXPECT_EQ(read.camera.fx_px, 800);
  EXPECT_EQ(read.pixel_noise_px, 0.05);
  ASSERT_EQ(read.check_distances.size(), 2u);
  EXPECT_EQ(read.check_distances[1].dot_b, 4);
  EXPECT_EQ(read.yardsticks[0].length_m, 0.1);
  const Status bad = ParseSetupFile(R"({"format":"selfcal-session-setup","version":2})", "x/setup.json", &read);
  EXPECT_TRUE(Contains(bad.message(), "x/setup.json:1: format must be selfcal-session-setup version 1")) << bad.message();
}

}  // namespace
}  // namespace selfcal::session
