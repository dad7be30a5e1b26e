// One rule for every output path (docs/cli-output.md "Output paths"): no command writes inside a session
// directory, over an input it reads, or over an existing file without --force, and every output path is
// checked before any work. The options come from the commands' own definitions (SELFCAL_LIST_OUTPUT_OPTIONS,
// app/output_options.h), so an output option added later is tested here without anyone listing it.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

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

using testing::Contains;

struct Output {
  int code = -1;
  std::string out, err;
};

// `selfcal arguments` run in `dir`, stdout and stderr apart; `environment` ("NAME=value ") before it.
Output RunIn(const fs::path& dir, const std::string& arguments, const std::string& environment = "") {
  Output result;
  const fs::path out = dir / ".stdout.txt", err = dir / ".stderr.txt";
  const std::string command = "cd " + dir.string() + " && " + environment + SELFCAL_BINARY + " " + arguments + " >" +
                              out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  result.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadFile(out.string());
  result.err = ReadFile(err.string());
  fs::remove(out);
  fs::remove(err);
  return result;
}

struct OutputOption {
  std::string command, option, kind;
};

// A command line that parses, every output of it a new path in the empty directory new/: (option, value) pairs, "" for a
// positional argument; and one file the command reads.
struct CommandLine {
  std::vector<std::pair<std::string, std::string>> arguments;
  std::string input;
};

// One recorded session, the files the commands read, and the output options of every command.
class OutputPathsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("selfcal_outputs_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_ / "in");
    testing::WriteShortPlan(*root_ / "in" / "plan.yaml", 6, 4);
    // The whole default plan: its calibration is accepted, so a camera file would be written (old code).
    setup_ = RunIn(*root_, "run --session s --seed 3");
    if (setup_.code != 0) return;
    setup_ = RunIn(*root_, "simulate --points --seed 3 --out sim");
    if (setup_.code != 0) return;
    fs::copy_file(*root_ / "sim" / "observations.yaml", *root_ / "in" / "obs.yaml");
    fs::copy_file(*root_ / "sim" / "calibrated_model.yaml", *root_ / "in" / "model.yaml");
    fs::copy_file(*root_ / "sim" / "report.json", *root_ / "in" / "report.json");
    fs::copy_file(std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml", *root_ / "in" / "robot.yaml");
    for (const char* name : {"targets.yaml", "image.png", "poses.txt", "tracker.csv"}) {
      WriteFile((*root_ / "in" / name).string(), "an input\n");
    }
    listing_ = RunIn(*root_, "", std::string(kListVariable) + "=1 ");
    std::istringstream lines(listing_.out);
    for (std::string line; std::getline(lines, line);) {
      const size_t a = line.find('\t'), b = line.rfind('\t');
      if (a != std::string::npos && b > a) options_->push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), line.substr(b + 1)});
    }
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(*root_, ignored);
    delete root_;
  }
  void SetUp() override { ASSERT_EQ(setup_.code, 0) << setup_.out << setup_.err; }

  static fs::path Session() { return *root_ / "s"; }

  // Runs `command` with `arguments`, `option` set to `value` (replacing its value there) and `extra`.
  static Output Run(const std::string& command, const CommandLine& line, const std::string& option,
                    const std::string& value, const std::string& extra) {
    std::string arguments = command;
    bool replaced = false;
    for (const auto& [name, given] : line.arguments) {
      const bool mine = name == option;
      replaced = replaced || mine;
      arguments += (name.empty() ? "" : " " + name) + " " + (mine ? value : given);
    }
    if (!replaced) arguments += " " + option + " " + value;
    return RunIn(*root_, arguments + extra);
  }

  static constexpr const char* kListVariable = "SELFCAL_LIST_OUTPUT_OPTIONS";
  static fs::path* root_;
  static Output setup_, listing_;
  static std::vector<OutputOption>* options_;
};
fs::path* OutputPathsTest::root_ = nullptr;
Output OutputPathsTest::setup_;
Output OutputPathsTest::listing_;
std::vector<OutputOption>* OutputPathsTest::options_ = new std::vector<OutputOption>();

// A parsing command line for each command (relative to the test's root); a command missing here fails
// the test below, so a new command cannot escape it either.
std::map<std::string, CommandLine> CommandLines() {
  return {
      {"calibrate", {{{"", "in/obs.yaml"}, {"--out", "new/cal"}}, "in/obs.yaml"}},
      {"compensate", {{{"", "in/model.yaml"}, {"--targets", "in/targets.yaml"}, {"--out", "new/j.yaml"}}, "in/targets.yaml"}},
      {"detect", {{{"--images", "in"}, {"--poses", "in/poses.txt"}, {"--out", "new/obs.yaml"}}, "in/poses.txt"}},
      {"name-dots", {{{"--image", "in/image.png"}, {"--setup", "new/setup.json"}, {"--out", "new/n.png"}}, "in/image.png"}},
      {"plan", {{{"--robot", "in/robot.yaml"}, {"--start", "in/plan.yaml"}, {"--out", "new/plan.yaml"}}, "in/plan.yaml"}},
      {"report", {{{"", "in/report.json"}, {"--out", "new/r.html"}}, "in/report.json"}},
      {"simulate", {{{"--robot", "in/robot.yaml"}, {"--trajectory", "in/plan.yaml"}, {"--out", "new/sim"}}, "in/plan.yaml"}},
      {"make-trajectory", {{{"--robot", "in/robot.yaml"}, {"--out", "new/t.yaml"}}, "in/robot.yaml"}},
      {"study", {{{"--trajectory", "in/plan.yaml"}, {"--out", "new/study.json"}}, "in/plan.yaml"}},
      {"identify-tracker",
       {{{"--data", "in"}, {"--file", "tracker.csv"}, {"--report", "new/t.json"}, {"--out", "new/m"}}, "in/tracker.csv"}},
      {"audit", {{{"", "s"}, {"--json", "new/a.json"}}, "s/session.json"}},
      {"run", {{{"--session", "new/run"}, {"--plan", "in/plan.yaml"}, {"--seed", "3"}}, "in/plan.yaml"}},
  };
}

// Inside the session: a file for a file output, the read-only inputs/ for the others.
std::string InsideSession(const std::string& kind) {
  if (kind == "file") return "s/journal.log";
  if (kind == "updated-file") return "s/inputs/robot.yaml";
  if (kind == "session") return "s/inner";
  return "s/inputs";
}

TEST_F(OutputPathsTest, TheListNamesTheKnownOutputOptionsOfEveryCommand) {
  ASSERT_EQ(listing_.code, 0) << listing_.out << listing_.err;
  std::vector<std::string> listed;
  for (const OutputOption& o : *options_) listed.push_back(o.command + " " + o.option);
  for (const char* known : {"calibrate --out", "calibrate --write-camera-opencv", "calibrate --write-camera-visp",
                            "compensate --out", "detect --out", "detect --contact-sheet", "detect --skipped-out", "name-dots --out",
                            "name-dots --setup", "plan --out", "report --out", "simulate --out", "make-trajectory --out",
                            "study --out", "identify-tracker --report", "identify-tracker --out", "audit --json",
                            "run --session"}) {
    EXPECT_NE(std::find(listed.begin(), listed.end(), known), listed.end()) << known << " is not listed:\n" << listing_.out;
  }
  // The list is not in the help.
  const Output help = RunIn(*root_, "--help");
  EXPECT_FALSE(Contains(help.out + help.err, kListVariable));
}

TEST_F(OutputPathsTest, EveryOutputOptionInsideASessionOrOnAnInputIsRefusedAndChangesNothing) {
  ASSERT_EQ(listing_.code, 0) << listing_.out << listing_.err;
  const std::map<std::string, CommandLine> lines = CommandLines();
  const std::map<std::string, std::string> session_before = TreeState(Session());
  const std::map<std::string, std::string> inputs_before = TreeState(*root_ / "in");
  ASSERT_GE(options_->size(), 17u);
  fs::create_directories(*root_ / "new");  // the other outputs' directory: it stays empty
  for (const OutputOption& o : *options_) {
    SCOPED_TRACE(o.command + " " + o.option + " (" + o.kind + ")");
    const auto line = lines.find(o.command);
    if (line == lines.end()) {
      ADD_FAILURE() << "no command line for `" << o.command << "` in CommandLines(): add one";
      continue;
    }
    const std::string force = o.kind == "file" || o.kind == "directory" ? " --force" : "";
    const Output inside = Run(o.command, line->second, o.option, InsideSession(o.kind), force);
    EXPECT_EQ(inside.code, 2) << inside.out << inside.err;
    EXPECT_TRUE(Contains(inside.err, o.option + " " + InsideSession(o.kind))) << inside.err;
    EXPECT_TRUE(Contains(inside.err, "inside the session directory")) << inside.err;
    EXPECT_EQ(TreeState(Session()), session_before);

    const Output input = Run(o.command, line->second, o.option, line->second.input, force);
    EXPECT_EQ(input.code, 2) << input.out << input.err;
    EXPECT_TRUE(Contains(input.err, o.option + " " + line->second.input)) << input.err;
    EXPECT_TRUE(Contains(input.err, "an input of this command") || Contains(input.err, "inside the session directory"))
        << input.err;
    EXPECT_EQ(TreeState(*root_ / "in"), inputs_before);
    EXPECT_EQ(TreeState(Session()), session_before);
    EXPECT_TRUE(fs::is_empty(*root_ / "new")) << "something was written before the refusal";
  }
  fs::remove_all(*root_ / "new");
}

// The campaign's reproducers: a mistyped camera path replaced the journal; a read-only input was replaced.
TEST_F(OutputPathsTest, CalibrateNeverWritesACameraFileIntoTheSessionItReads) {
  const std::map<std::string, std::string> before = TreeState(Session());
  for (const std::string option : {"--write-camera-opencv s/journal.log", "--write-camera-visp s/inputs/robot.yaml",
                                    "--write-camera-opencv s/images/../session.json"}) {
    const Output out = RunIn(*root_, "calibrate s --out new/cal " + option);
    EXPECT_EQ(out.code, 2) << option << "\n" << out.out << out.err;
    EXPECT_TRUE(Contains(out.err, option)) << out.err;
    EXPECT_FALSE(Contains(out.out, "accepted samples")) << "the session was read before the refusal: " << out.out;
  }
  EXPECT_EQ(TreeState(Session()), before);
  EXPECT_FALSE(fs::exists(*root_ / "new"));
}

TEST_F(OutputPathsTest, ReportPlanMakeTrajectoryAndSimulateNeverWriteIntoASession) {
  const std::map<std::string, std::string> before = TreeState(Session());
  for (const std::string command :
       {"report in/report.json --out s/report.html", "plan --robot in/robot.yaml --out s/plan.yaml",
        "make-trajectory --robot in/robot.yaml --out s/inputs/plan.yaml", "simulate --points --out s",
        "simulate --points --out s/sim"}) {
    const Output out = RunIn(*root_, command);
    EXPECT_EQ(out.code, 2) << command << "\n" << out.out << out.err;
    EXPECT_TRUE(Contains(out.err, "session directory")) << command << "\n" << out.err;
  }
  EXPECT_EQ(TreeState(Session()), before);
}

TEST_F(OutputPathsTest, ASessionIsNeverCreatedInsideAnother) {
  const std::map<std::string, std::string> before = TreeState(Session());
  const Output out = RunIn(*root_, "run --session s/images/nested --seed 3 --plan in/plan.yaml");
  EXPECT_EQ(out.code, 2) << out.out << out.err;
  EXPECT_TRUE(Contains(out.err, "--session s/images/nested")) << out.err;
  EXPECT_EQ(TreeState(Session()), before);
}

// A bad --write-camera-* path was found after the solve, with the model already written.
TEST_F(OutputPathsTest, ABadCameraPathIsRefusedBeforeTheSolveWithNothingWritten) {
  for (const std::string option : {"--write-camera-opencv in/obs.yaml/camera.yaml", "--write-camera-visp in",
                                    "--write-camera-opencv in/robot.yaml"}) {
    const Output out = RunIn(*root_, "calibrate in/obs.yaml --out new/cal " + option);
    EXPECT_EQ(out.code, 2) << option << "\n" << out.out << out.err;
    EXPECT_TRUE(Contains(out.err, option)) << out.err;
    EXPECT_FALSE(fs::exists(*root_ / "new" / "cal")) << "written before the refusal: " << out.out;
  }
  fs::remove_all(*root_ / "new");
}

TEST_F(OutputPathsTest, AnEarlierRunsOutputsAreReplacedOnlyWithForce) {
  const Output first = RunIn(*root_, "calibrate in/obs.yaml --out again");
  ASSERT_EQ(first.code, 0) << first.out << first.err;
  WriteFile((*root_ / "again" / "report.json").string(), "mine\n");
  const Output second = RunIn(*root_, "calibrate in/obs.yaml --out again");
  EXPECT_EQ(second.code, 2) << second.out << second.err;
  EXPECT_TRUE(Contains(second.err, "--out again")) << second.err;
  EXPECT_TRUE(Contains(second.err, "--force")) << second.err;
  EXPECT_EQ(ReadFile((*root_ / "again" / "report.json").string()), "mine\n");
  const Output forced = RunIn(*root_, "calibrate in/obs.yaml --out again --force");
  EXPECT_EQ(forced.code, 0) << forced.out << forced.err;
  EXPECT_NE(ReadFile((*root_ / "again" / "report.json").string()), "mine\n");

  // A forced run that writes no model (f_x held 2 % off: refused) removes the earlier run's model: it would sit
  // beside a report that says rejected.
  ASSERT_TRUE(fs::exists(*root_ / "again" / "calibrated_model.yaml"));
  std::string observations = ReadFile((*root_ / "in" / "obs.yaml").string());
  const size_t fx = observations.find("fx_px: 1000,");
  ASSERT_NE(fx, std::string::npos);
  observations.replace(fx, 12, "fx_px: 1020,");
  WriteFile((*root_ / "fx_off.yaml").string(), observations);
  const Output refused = RunIn(*root_, "calibrate fx_off.yaml --out again --force --fix fx");
  EXPECT_EQ(refused.code, 6) << refused.out << refused.err;
  EXPECT_FALSE(fs::exists(*root_ / "again" / "calibrated_model.yaml"));
  EXPECT_FALSE(fs::exists(*root_ / "again" / "calibrated.urdf"));
  EXPECT_TRUE(Contains(refused.out, "removed the earlier run's")) << refused.out;

  WriteFile((*root_ / "mine.yaml").string(), "mine\n");
  const Output trajectory = RunIn(*root_, "make-trajectory --robot in/robot.yaml --out mine.yaml");
  EXPECT_EQ(trajectory.code, 2) << trajectory.out << trajectory.err;
  EXPECT_EQ(ReadFile((*root_ / "mine.yaml").string()), "mine\n");
  EXPECT_EQ(RunIn(*root_, "make-trajectory --robot in/robot.yaml --out mine.yaml --force").code, 0);
  EXPECT_NE(ReadFile((*root_ / "mine.yaml").string()), "mine\n");
}

}  // namespace
}  // namespace selfcal
