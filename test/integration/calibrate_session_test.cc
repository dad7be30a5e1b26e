// `selfcal calibrate SESSION --out DIR` reads a recorded session and changes nothing in it
// (docs/session-format.md, "Reading a session offline"): not a torn journal tail, not an unrecorded image,
// not the lock. A modified input is refused, and so is an output directory inside the session.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "base/sha256.h"
#include "support/cli.h"
#include "support/temp_files.h"
#include "support/tree_state.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::TreeState;
using testing::WriteFile;

// Runs the selfcal binary with arguments; returns its exit code, stdout and stderr in *output.
int RunSelfcal(const std::string& arguments, std::string* output) { return testing::RunSelfcal(arguments, output); }

using testing::Contains;

// One recorded session (simulated arm, default plan, seed 1) shared by the tests, each of which works on
// its own copy.
class CalibrateSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("selfcal_calsession_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    std::string output;
    recorded_ = RunSelfcal("run --session " + (*root_ / "recorded").string() + " --seed 1", &output);
    if (recorded_ != 0) std::cerr << output;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::permissions(*root_, fs::perms::owner_all, fs::perm_options::add, ignored);
    for (const auto& entry : fs::recursive_directory_iterator(*root_, ignored)) {
      fs::permissions(entry.path(), fs::perms::owner_write, fs::perm_options::add, ignored);
    }
    fs::remove_all(*root_, ignored);
    delete root_;
  }
  void SetUp() override { ASSERT_EQ(recorded_, 0) << "selfcal run --session ... --seed 1 failed"; }

  // A copy of the recorded session named `name`, with its modes (inputs/ stay 0444).
  fs::path CopyOfSession(const std::string& name) {
    const fs::path copy = *root_ / name;
    fs::copy(*root_ / "recorded", copy, fs::copy_options::recursive);
    return copy;
  }

  static fs::path* root_;
  static int recorded_;
};
fs::path* CalibrateSessionTest::root_ = nullptr;
int CalibrateSessionTest::recorded_ = -1;

TEST_F(CalibrateSessionTest, CalibratingLeavesEveryByteOfTheSessionUnchanged) {
  const fs::path session = CopyOfSession("untidy");
  // A torn tail (a record cut short by a crash) and an image no record names.
  const std::string journal = ReadFile((session / "journal.log").string());
  WriteFile((session / "journal.log").string(), journal + "J1 00000030 0badc0de {\"type\":\"fini");
  fs::copy_file(session / "images" / "p00_0.png", session / "images" / "p00_copy.png");
  const auto before = TreeState(session);

  std::string output;
  EXPECT_EQ(RunSelfcal("calibrate " + session.string() + " --out " + (*root_ / "untidy-cal").string(), &output), 0)
      << output;
  EXPECT_EQ(TreeState(session), before) << output;
  EXPECT_FALSE(fs::exists(session / "orphans"));
  EXPECT_TRUE(Contains(output, "torn tail of 34 bytes at byte offset " + std::to_string(journal.size()))) << output;
  EXPECT_TRUE(Contains(output, "would be truncated on resume")) << output;
  EXPECT_TRUE(Contains(output, (session / "images" / "p00_copy.png").string() + " is named by no journal record"))
      << output;
  EXPECT_TRUE(Contains(output, "would be moved to orphans/ on resume")) << output;
  EXPECT_TRUE(Contains(output, "calibrate changed nothing in session")) << output;
  EXPECT_TRUE(fs::exists(*root_ / "untidy-cal" / "calibrated_model.yaml")) << output;
}

TEST_F(CalibrateSessionTest, AModifiedInputIsRefusedNamingIt) {
  const fs::path session = CopyOfSession("tampered");
  const fs::path robot = session / "inputs" / "robot.yaml";
  std::string text = ReadFile(robot.string());
  const std::size_t at = text.find("a_mm: 431.8");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 11, "a_mm: 441.8");
  fs::permissions(robot, fs::perms::owner_write, fs::perm_options::add);
  WriteFile(robot.string(), text);
  const auto before = TreeState(session);

  std::string output;
  EXPECT_EQ(RunSelfcal("calibrate " + session.string() + " --out " + (*root_ / "tampered-cal").string(), &output), 2)
      << output;
  EXPECT_TRUE(Contains(output, robot.string() + ": differs from the size or SHA-256 recorded in session.json"))
      << output;
  EXPECT_EQ(TreeState(session), before);
  EXPECT_FALSE(fs::exists(*root_ / "tampered-cal" / "calibrated_model.yaml"));
}

TEST_F(CalibrateSessionTest, AnOutputDirectoryInsideTheSessionIsRefused) {
  const fs::path session = CopyOfSession("inside");
  fs::create_directory_symlink(session, *root_ / "link-to-inside");
  const auto before = TreeState(session);
  for (const fs::path& out : {session, session / "images", session / "new" / "cal", *root_ / "link-to-inside" / "cal",
                              fs::path(session.string() + "/images/../out")}) {
    std::string output;
    EXPECT_EQ(RunSelfcal("calibrate " + session.string() + " --out " + out.string(), &output), 2) << out << output;
    EXPECT_TRUE(Contains(output, "--out " + out.string())) << output;
    EXPECT_TRUE(Contains(output, "session directory")) << output;
    EXPECT_TRUE(Contains(output, "no command writes into a session")) << output;
  }
  EXPECT_EQ(TreeState(session), before);
  // Beside the session is fine.
  std::string output;
  EXPECT_EQ(RunSelfcal("calibrate " + session.string() + " --out " + session.string() + "-cal", &output), 0) << output;
  EXPECT_EQ(TreeState(session), before);
}

}  // namespace
}  // namespace selfcal
