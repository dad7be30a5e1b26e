#include "session/output_path.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "session/session_test_util.h"

namespace selfcal::session {
namespace {

using testing::Contains;
using testing::CreateTestSession;
using testing::ReadFile;
using testing::TempDir;
using testing::WriteFile;

namespace fs = std::filesystem;

// A real session (session.json, journal.log, inputs/ read-only) at dir/s; its path.
std::string MakeSession(const TempDir& dir) {
  const std::string path = dir.File("s");
  { Result<Session> session = CreateTestSession(path); }
  return path;
}

Status Check(const std::string& path, OutputKind kind, bool force = false, const std::vector<std::string>& inputs = {},
             const std::vector<std::string>& files = {}) {
  return CheckOutputPath(OutputPath{"--out", path, kind, files}, inputs, force);
}

TEST(EnclosingSession, FindsTheSessionOfEveryPathInsideItAndNoneOutside) {
  TempDir dir;
  const std::string s = fs::canonical(MakeSession(dir)).string();
  EXPECT_EQ(EnclosingSession(s), s);
  EXPECT_EQ(EnclosingSession(s + "/journal.log"), s);
  EXPECT_EQ(EnclosingSession(s + "/inputs/robot.yaml"), s);
  EXPECT_EQ(EnclosingSession(s + "/new/deeper/file.yaml"), s);
  EXPECT_EQ(EnclosingSession(dir.File("other/../s/images/x.png")), s);
  EXPECT_EQ(EnclosingSession(dir.File("out.yaml")), "");
  EXPECT_EQ(EnclosingSession(dir.path()), "");
  fs::create_directory_symlink(s, dir.File("link"));
  EXPECT_EQ(EnclosingSession(dir.File("link/journal.log")), s);
}

TEST(CheckOutputPath, RefusesEveryPathInsideASessionEvenWithForceAndNamesOptionAndSession) {
  TempDir dir;
  const std::string s = MakeSession(dir);
  const std::string journal = ReadFile(s + "/journal.log");
  for (const OutputKind kind : {OutputKind::kFile, OutputKind::kFileAndParents, OutputKind::kDirectory,
                                OutputKind::kUpdatedFile, OutputKind::kSessionDirectory}) {
    for (const std::string& path : {s + "/journal.log", s + "/inputs/robot.yaml", s + "/images/new", s + "/x/y"}) {
      const Status status = Check(path, kind, /*force=*/true);
      ASSERT_FALSE(status.ok()) << path;
      EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
      EXPECT_TRUE(Contains(status.message(), "--out " + path)) << status.message();
      EXPECT_TRUE(Contains(status.message(), "inside the session directory")) << status.message();
    }
  }
  EXPECT_TRUE(Contains(Check(s, OutputKind::kDirectory, true).message(), "is the session directory"));
  EXPECT_TRUE(Contains(Check(s + "/", OutputKind::kFile, true).message(), "is the session directory"));
  EXPECT_TRUE(Contains(Check(s + "/images/..", OutputKind::kDirectory, true).message(), "is the session directory"));
  EXPECT_EQ(ReadFile(s + "/journal.log"), journal);
}

TEST(CheckOutputPath, ASessionDirectoryMayBeTheSessionItselfButNotInsideAnother) {
  TempDir dir;
  const std::string s = MakeSession(dir);
  EXPECT_TRUE(Check(s, OutputKind::kSessionDirectory).ok());  // a resume; run itself refuses a new one there
  EXPECT_TRUE(Check(dir.File("new/session"), OutputKind::kSessionDirectory).ok());
  EXPECT_FALSE(Check(s + "/inner", OutputKind::kSessionDirectory).ok());
  WriteFile(dir.File("file"), "x");
  EXPECT_FALSE(Check(dir.File("file"), OutputKind::kSessionDirectory).ok());
}

TEST(CheckOutputPath, AnExistingFileIsReplacedOnlyWithForce) {
  TempDir dir;
  WriteFile(dir.File("out.yaml"), "old");
  const Status refused = Check(dir.File("out.yaml"), OutputKind::kFile);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(Contains(refused.message(), "exists; give --force")) << refused.message();
  EXPECT_TRUE(Check(dir.File("out.yaml"), OutputKind::kFile, true).ok());
  EXPECT_TRUE(Check(dir.File("new.yaml"), OutputKind::kFile).ok());
  EXPECT_FALSE(Check(dir.path(), OutputKind::kFile, true).ok());  // a directory is never a file output
}

TEST(CheckOutputPath, AFileNeedsAnExistingWritableDirectoryUnlessItsParentsAreCreated) {
  TempDir dir;
  const Status missing = Check(dir.File("no/such/dir/camera.yaml"), OutputKind::kFile);
  ASSERT_FALSE(missing.ok());
  EXPECT_TRUE(Contains(missing.message(), "does not exist or is not writable")) << missing.message();
  EXPECT_TRUE(Check(dir.File("no/such/dir/plan.yaml"), OutputKind::kFileAndParents).ok());
  WriteFile(dir.File("plain"), "x");
  EXPECT_FALSE(Check(dir.File("plain/below.yaml"), OutputKind::kFileAndParents).ok());
  if (::geteuid() != 0) {  // root writes anywhere
    fs::create_directory(dir.File("ro"));
    ::chmod(dir.File("ro").c_str(), 0555);
    EXPECT_FALSE(Check(dir.File("ro/x.yaml"), OutputKind::kFile).ok());
    EXPECT_FALSE(Check(dir.File("ro/sub"), OutputKind::kDirectory).ok());
    ::chmod(dir.File("ro").c_str(), 0755);
  }
}

TEST(CheckOutputPath, AnInputIsNeverAnOutputEvenWithForce) {
  TempDir dir;
  WriteFile(dir.File("obs.yaml"), "x");
  fs::create_hard_link(dir.File("obs.yaml"), dir.File("hard.yaml"));
  for (const std::string& path : {dir.File("obs.yaml"), dir.File("hard.yaml"), dir.File("sub/../obs.yaml")}) {
    const Status status = Check(path, OutputKind::kFile, true, {dir.File("obs.yaml")});
    ASSERT_FALSE(status.ok()) << path;
    EXPECT_TRUE(Contains(status.message(), "an input of this command")) << status.message();
  }
  const Status in_dir =
      Check(dir.path(), OutputKind::kDirectory, true, {dir.File("obs.yaml")}, {"report.json", "obs.yaml"});
  ASSERT_FALSE(in_dir.ok());
  EXPECT_TRUE(Contains(in_dir.message(), "would replace obs.yaml")) << in_dir.message();
  EXPECT_TRUE(Check(dir.File("other.yaml"), OutputKind::kFile, false, {dir.File("obs.yaml"), dir.File("gone")}).ok());
}

TEST(CheckOutputPath, ADirectoryHoldingAFileTheCommandWritesIsRefusedWithoutForce) {
  TempDir dir;
  fs::create_directory(dir.File("out"));
  WriteFile(dir.File("out/notes.txt"), "mine");
  const std::vector<std::string> files = {"report.json", "calibrated_model.yaml"};
  EXPECT_TRUE(Check(dir.File("out"), OutputKind::kDirectory, false, {}, files).ok());
  WriteFile(dir.File("out/report.json"), "{}");
  const Status refused = Check(dir.File("out"), OutputKind::kDirectory, false, {}, files);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(Contains(refused.message(), "holds report.json")) << refused.message();
  EXPECT_TRUE(Check(dir.File("out"), OutputKind::kDirectory, true, {}, files).ok());
  EXPECT_TRUE(Check(dir.File("new/deeper"), OutputKind::kDirectory, false, {}, files).ok());
  EXPECT_FALSE(Check(dir.File("out/notes.txt"), OutputKind::kDirectory, true, {}, files).ok());
}

TEST(CheckOutputPath, AnEmptyPathIsNotWrittenAndNotChecked) {
  EXPECT_TRUE(Check("", OutputKind::kFile).ok());
}

}  // namespace
}  // namespace selfcal::session
