// An interrupted creation, a session that recorded nothing and a recorded session told apart, and removed
// only when nothing was recorded (docs/session-format.md, "Interrupted creation").
#include "session/session_cleanup.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "session/session_test_util.h"

namespace selfcal::session {
namespace {

namespace fs = std::filesystem;
using testing::Contains;
using testing::CreateTestSession;
using testing::TempDir;
using testing::TestInputs;

nlohmann::json Started() {
  return {{"type", "session_started"}, {"time_s", 0.0}, {"num_poses", 1}, {"mode", "simulated"}};
}

// What a kill inside CreateSession leaves: the directory, the lock, some inputs and a temporary file.
void MakeInterruptedCreation(const std::string& path, const std::string& robot_yaml) {
  fs::create_directories(path + "/inputs");
  testing::WriteFile(path + "/lock", "");
  testing::WriteFile(path + "/inputs/config.yaml", TestInputs()[0].contents);
  testing::WriteFile(path + "/inputs/.robot.yaml.tmp.AbC123", robot_yaml);
}

TEST(SessionCleanup, TellsTheStatesApart) {
  TempDir dir;
  EXPECT_EQ(InspectSessionDir(dir.path() + "/none")->state, SessionDirState::kAbsent);
  fs::create_directories(dir.path() + "/empty");
  EXPECT_EQ(InspectSessionDir(dir.path() + "/empty")->state, SessionDirState::kEmpty);

  const std::string cut = dir.path() + "/cut";
  MakeInterruptedCreation(cut, "name: puma560\n");
  Result<SessionDirInspection> in = InspectSessionDir(cut);
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->state, SessionDirState::kInterruptedCreation);
  ASSERT_EQ(in->recorded_inputs.size(), 1u);  // the temporary file is not an input
  EXPECT_TRUE(DifferingInputs(*in, TestInputs()).empty());
  SessionInputs other = TestInputs();
  other[0].contents = "mode: real\n";
  EXPECT_EQ(DifferingInputs(*in, other), std::vector<std::string>{"config.yaml"});

  const std::string fresh = dir.path() + "/fresh";
  {
    Result<Session> s = CreateTestSession(fresh);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(InspectSessionDir(fresh)->state, SessionDirState::kNothingRecorded);
    ASSERT_TRUE(s.value().journal().Append(Started()).ok());
    EXPECT_EQ(InspectSessionDir(fresh)->state, SessionDirState::kNothingRecorded);  // started, no frame
    ASSERT_TRUE(s.value().WriteImage("p00_0.png", "png").ok());
    EXPECT_EQ(InspectSessionDir(fresh)->state, SessionDirState::kRecorded);  // an image is recorded data
  }
}

TEST(SessionCleanup, DiscardRemovesOnlyWhatRecordedNothing) {
  TempDir dir;
  const std::string cut = dir.path() + "/cut";
  MakeInterruptedCreation(cut, "x");
  ASSERT_TRUE(DiscardSession(cut, false).ok());
  EXPECT_FALSE(fs::exists(cut));

  const std::string started = dir.path() + "/started";
  {
    Result<Session> s = CreateTestSession(started);
    ASSERT_TRUE(s.ok());
    ASSERT_TRUE(s.value().journal().Append(Started()).ok());
    const Status busy = DiscardSession(started, false);  // the lock is held by the open session
    EXPECT_FALSE(busy.ok());
    EXPECT_TRUE(Contains(busy.message(), "in use")) << busy.message();
  }
  ASSERT_TRUE(DiscardSession(started, false).ok());
  EXPECT_FALSE(fs::exists(started));

  const std::string recorded = dir.path() + "/recorded";
  {
    Result<Session> s = CreateTestSession(recorded);
    ASSERT_TRUE(s.ok());
    ASSERT_TRUE(s.value().WriteImage("p00_0.png", "png").ok());
  }
  const Status refused = DiscardSession(recorded, false);
  EXPECT_EQ(refused.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(refused.message(), "recorded data")) << refused.message();
  EXPECT_TRUE(fs::exists(recorded + "/images/p00_0.png"));

  const std::string foreign = dir.path() + "/foreign";
  MakeInterruptedCreation(foreign, "x");
  testing::WriteFile(foreign + "/notes.txt", "mine");
  const Status kept = DiscardSession(foreign, false);
  EXPECT_FALSE(kept.ok());
  EXPECT_TRUE(Contains(kept.message(), "notes.txt")) << kept.message();
  EXPECT_TRUE(fs::exists(foreign + "/notes.txt"));
  EXPECT_FALSE(DiscardSession(dir.path() + "/none", false).ok());
}

}  // namespace
}  // namespace selfcal::session
