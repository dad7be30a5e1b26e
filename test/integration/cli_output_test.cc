// The command line's output modes: `--json` (one JSON document on stdout, checked against the files the
// command wrote), the progress line (never in a stderr that is not a terminal; drawn on a terminal),
// defaults in --help and suggestions for mistyped commands and options (docs/cli-output.md).
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::FreshDir;

using testing::ReadFile;
using testing::WriteFile;
using testing::WriteShortPlan;

// `selfcal arguments` from the source tree (its config/ paths), stdout and stderr apart.
struct Output {
  int code = -1;
  std::string out, err;
};
Output RunSplit(const std::string& arguments, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  Output result;
  const std::string command =
      "cd " + std::string(SELFCAL_SOURCE_DIR) + " && " + SELFCAL_BINARY + " " + arguments + " 2>" + err.string();
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;) result.out.append(buffer, n);
  const int status = ::pclose(pipe);
  result.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = ReadFile(err.string());
  return result;
}

// stdout as exactly one JSON document (parse throws on anything before or after it).
json Document(const Output& output) {
  json document;
  EXPECT_NO_THROW(document = json::parse(output.out)) << "stdout:\n" << output.out << "\nstderr:\n" << output.err;
  return document;
}

void ExpectCommon(const json& d, const std::string& command, int code) {
  EXPECT_EQ(d.at("format"), "selfcal-cli-result");
  EXPECT_EQ(d.at("version"), 1);
  EXPECT_EQ(d.at("command"), command);
  EXPECT_EQ(d.at("exit_code"), code);
  EXPECT_TRUE(d.at("outcome").is_string());
  for (const auto& [role, path] : d.at("files").items()) {
    const fs::path p = fs::path(path.get<std::string>());
    EXPECT_TRUE(fs::exists(p.is_absolute() ? p : fs::path(SELFCAL_SOURCE_DIR) / p)) << role << ": " << p;
  }
}

bool HasControlCharacters(const std::string& text) {
  return text.find('\r') != std::string::npos || text.find('\x1b') != std::string::npos;
}

TEST(CliJson, SimulatePointsAndCalibrateMatchTheirReports) {
  const fs::path dir = FreshDir("cli_json", "calibrate");
  const Output sim = RunSplit("simulate --points --seed 3 --json --out " + (dir / "sim").string(), dir);
  ASSERT_EQ(sim.code, 0) << sim.err;
  const json s = Document(sim);
  ExpectCommon(s, "simulate", 0);
  EXPECT_EQ(s.at("outcome"), "accepted");
  EXPECT_EQ(s.at("files").at("observations"), (dir / "sim" / "observations.yaml").string());
  EXPECT_TRUE(s.at("comparison_with_truth").contains("bundle"));

  const fs::path out = dir / "cal";
  const Output cal = RunSplit("calibrate " + (dir / "sim" / "observations.yaml").string() + " --json --out " + out.string(), dir);
  ASSERT_EQ(cal.code, 0) << cal.err;
  const json d = Document(cal);
  ExpectCommon(d, "calibrate", 0);
  const json report = json::parse(ReadFile((out / "report.json").string()));
  EXPECT_EQ(d.at("outcome"), report.at("verdict"));
  EXPECT_EQ(d.at("files").at("report"), (out / "report.json").string());
  EXPECT_EQ(d.at("files").at("calibrated_model"), (out / "calibrated_model.yaml").string());
  EXPECT_EQ(d.at("files").at("calibrated_urdf"), (out / "calibrated.urdf").string());
  const json& c = d.at("calibration");
  for (const char* key : {"verdict", "method", "accepted", "reasons", "fx_px", "heldout_reprojection"}) {
    EXPECT_EQ(c.at(key), report.at(key)) << key;
  }
  EXPECT_EQ(c.at("method"), "bundle");
  EXPECT_GT(c.at("heldout_reprojection").at("calibrated_model").at("overall").at("rms_px").get<double>(), 0);
  EXPECT_TRUE(c.at("heldout_reprojection").at("test_passed").get<bool>());
  EXPECT_EQ(sim.err.find("report: "), std::string::npos);  // human text is not moved to stderr either
}

// The last line of stdout without --json.
std::string LastLine(const std::string& out) {
  if (out.empty() || out.back() != '\n') return "(stdout does not end with a line)";
  const size_t start = out.rfind('\n', out.size() - 2);
  return out.substr(start == std::string::npos ? 0 : start + 1, out.size() - 1 - (start == std::string::npos ? 0 : start + 1));
}

// calibrate's last stdout line: the verdict word, the held-out figure in px and mm at the scene, the files
// written; for an accepted run and a refused one (the same images with a pixel noise stated 20 times too
// small). No line of the accepted run reads like a failed test.
TEST(CliFinalLine, CalibrateEndsWithTheVerdictTheFigureAndTheFiles) {
  const fs::path dir = FreshDir("cli_final_line", "calibrate");
  const Output sim = RunSplit("simulate --points --seed 3 --quiet --out " + (dir / "sim").string(), dir);
  ASSERT_EQ(sim.code, 0) << sim.err;
  EXPECT_EQ(LastLine(sim.out).rfind("accepted: held-out ", 0), 0u) << sim.out;
  const std::string observations = (dir / "sim" / "observations.yaml").string();
  const Output ok = RunSplit("calibrate " + observations + " --quiet --out " + (dir / "ok").string(), dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  const json report = json::parse(ReadFile((dir / "ok" / "report.json").string()));
  const json& heldout = report.at("heldout_reprojection").at("calibrated_model");
  std::ostringstream figure;
  figure << std::fixed << std::setprecision(3) << "accepted: held-out " << heldout.at("overall").at("rms_px").get<double>()
         << " px (" << heldout.at("rms_m").get<double>() * 1e3 << " mm at the scene) on "
         << heldout.at("poses").size() << " verification poses; wrote " << (dir / "ok").string() << "/: ";
  const std::string last = LastLine(ok.out);
  EXPECT_EQ(last.rfind(figure.str(), 0), 0u) << last << "\nexpected to start with\n" << figure.str();
  for (const char* name : {"report.json/html", "image_residuals.csv", "calibrated_model.yaml", "calibrated.urdf"}) {
    EXPECT_NE(last.find(name), std::string::npos) << name << " in " << last;
  }
  EXPECT_EQ(ok.out.find(" > "), std::string::npos) << ok.out;  // no "chi-square 201.6 > 191.9"
  EXPECT_EQ(ok.out.find("failed"), std::string::npos) << ok.out;

  std::string small = ReadFile(observations);
  const size_t noise = small.find("pixel_noise_px: 0.2\n");
  ASSERT_NE(noise, std::string::npos);
  small.replace(noise, std::string("pixel_noise_px: 0.2").size(), "pixel_noise_px: 0.01");
  WriteFile((dir / "small_noise.yaml").string(), small);
  const Output refused =
      RunSplit("calibrate " + (dir / "small_noise.yaml").string() + " --quiet --out " + (dir / "refused").string(), dir);
  ASSERT_EQ(refused.code, 6) << refused.err;
  const std::string refused_last = LastLine(refused.out);
  EXPECT_EQ(refused_last.rfind("rejected: held-out ", 0), 0u) << refused_last;
  EXPECT_NE(refused_last.find(" px ("), std::string::npos) << refused_last;
  EXPECT_NE(refused_last.find("wrote " + (dir / "refused").string() + "/: report.json/html"), std::string::npos)
      << refused_last;
  EXPECT_EQ(refused_last.find("calibrated_model.yaml"), std::string::npos) << refused_last;
}

TEST(CliJson, AnErrorStillPrintsTheDocumentWithTheMessage) {
  const fs::path dir = FreshDir("cli_json", "error");
  const Output cal = RunSplit("calibrate " + (dir / "missing.yaml").string() + " --json --out " + dir.string(), dir);
  EXPECT_EQ(cal.code, 2);
  const json d = Document(cal);
  ExpectCommon(d, "calibrate", 2);
  EXPECT_EQ(d.at("outcome"), "usage_or_config");
  EXPECT_NE(d.at("error").get<std::string>().find("missing.yaml"), std::string::npos) << d.dump();
  EXPECT_NE(cal.err.find("missing.yaml"), std::string::npos);  // and the sentence on stderr as text

  const Output typo = RunSplit("calibrate --metod paper --json", dir);  // a usage error before any command ran
  EXPECT_EQ(typo.code, 2);
  const json t = Document(typo);
  EXPECT_EQ(t.at("exit_code"), 2);
  EXPECT_NE(t.at("error").get<std::string>().find("--method"), std::string::npos) << t.dump();
}

TEST(CliJson, PlanGivesTheCriterionAndObservability) {
  const fs::path dir = FreshDir("cli_json", "plan");
  const fs::path plan = dir / "plan.yaml";
  const Output p = RunSplit("plan --criterion d-optimal --seed 4 --json --out " + plan.string(), dir);
  ASSERT_EQ(p.code, 0) << p.err;
  const json d = Document(p);
  ExpectCommon(d, "plan", 0);
  EXPECT_EQ(d.at("files").at("plan"), plan.string());
  EXPECT_EQ(d.at("plan").at("criterion"), "d-optimal");
  EXPECT_GE(d.at("plan").at("d_optimal_log_det").at("planned").get<double>(),
            d.at("plan").at("d_optimal_log_det").at("start").get<double>());
  EXPECT_TRUE(d.at("plan").at("check_final").at("ok").get<bool>());
  EXPECT_GT(d.at("observability").at("condition_number").get<double>(), 1);
  EXPECT_EQ(d.at("observability").at("predicted_stddev").size(), d.at("observability").at("columns").get<size_t>());
  EXPECT_NE(ReadFile(plan.string()).find("d-optimal"), std::string::npos);  // the file it names is the plan it made

  const Output check = RunSplit("plan --check " + plan.string() + " --json", dir);
  ASSERT_EQ(check.code, 0) << check.err;
  const json c = Document(check);
  ExpectCommon(c, "plan", 0);
  EXPECT_EQ(c.at("outcome"), "plan_ok");
  EXPECT_DOUBLE_EQ(c.at("observability").at("condition_number").get<double>(),
                   d.at("observability").at("condition_number").get<double>());
}

TEST(CliJson, RunCountsTheSamplesOfTheSessionItWrote) {
  const fs::path dir = FreshDir("cli_json", "run");
  WriteShortPlan(dir / "plan.yaml", 6, 4);
  const fs::path session = dir / "session";
  const Output r = RunSplit("run --backend sim --camera sim --seed 2 --json --plan " + (dir / "plan.yaml").string() +
                                " --session " + session.string(),
                            dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const json d = Document(r);
  ExpectCommon(d, "run", 0);
  EXPECT_EQ(d.at("outcome"), "completed");
  EXPECT_EQ(d.at("files").at("session"), session.string());
  EXPECT_EQ(d.at("run").at("session"), session.string());
  EXPECT_EQ(d.at("run").at("samples_accepted"), 6);
  EXPECT_TRUE(d.at("run").at("samples_skipped").empty());
  int accepted = 0;  // the journal's sample records agree
  std::ifstream journal(session / "journal.log", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(journal)), std::istreambuf_iterator<char>());
  for (size_t at = 0; (at = bytes.find("\"sample_accepted\"", at)) != std::string::npos; ++at) ++accepted;
  EXPECT_EQ(accepted, 6);
}

TEST(CliJson, DetectCountsImagesAndPoints) {
  const fs::path dir = FreshDir("cli_json", "detect");
  const fs::path obs = dir / "ros.yaml";
  const Output r = RunSplit(
      "detect --images test/data/ros-industrial-dotgrid-10x10/images --poses test/data/ros-industrial-dotgrid-10x10/poses "
      "--camera-fx-px 542.3 --camera-cx-px 320.474 --camera-cy-px 226.039 --json --out " + obs.string() +
          " --contact-sheet " + (dir / "sheet.png").string(),
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const json d = Document(r);
  ExpectCommon(d, "detect", 0);
  EXPECT_EQ(d.at("files").at("observations"), obs.string());
  EXPECT_EQ(d.at("files").at("contact_sheet"), (dir / "sheet.png").string());
  const json& f = d.at("detect");
  EXPECT_EQ(f.at("per_image").size(), f.at("images").get<size_t>());
  int points = 0, with_points = 0;
  for (const json& image : f.at("per_image")) {
    points += image.at("points").get<int>();
    with_points += image.at("ok").get<bool>() ? 1 : 0;
  }
  EXPECT_EQ(f.at("points"), points);
  EXPECT_EQ(f.at("images_with_points"), with_points);
  EXPECT_GE(points, 50 * with_points);  // most of a 10 x 10 grid in every image it names
  EXPECT_GT(with_points, 0);
  // The observations file holds one pose per image with points.
  const std::string text = ReadFile(obs.string());
  size_t poses = 0;
  for (size_t at = 0; (at = text.find("\n  - id:", at)) != std::string::npos; ++at) ++poses;
  EXPECT_EQ(static_cast<int>(poses), with_points) << "the observations file's pose rows";
}

TEST(CliJson, StudyHoldsTheTablesOfItsFile) {
  const fs::path dir = FreshDir("cli_json", "study");
  const fs::path out = dir / "study.json";
  const Output r = RunSplit("study --runs 2 --noise-px 0.2 --no-bound --no-opencv --no-bundle --json --out " + out.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const json d = Document(r);
  ExpectCommon(d, "study", 0);
  EXPECT_EQ(d.at("files").at("study"), out.string());
  json file = json::parse(ReadFile(out.string()));
  json figures = d.at("study");
  file.erase("seconds_total");  // timing may differ in its last digits only if written twice; it is not
  figures.erase("seconds_total");
  EXPECT_EQ(figures, file);
}

TEST(CliProgress, NoProgressControlCharactersWhenStderrIsNotATerminal) {
  const fs::path dir = FreshDir("cli_progress", "pipe");
  const Output r = RunSplit("study --runs 3 --noise-px 0.2 --no-bound --no-opencv --out " + (dir / "s.json").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(HasControlCharacters(r.err)) << r.err;
  EXPECT_FALSE(HasControlCharacters(r.out));
  const Output sim = RunSplit("simulate --points --seed 3 --out " + (dir / "sim").string(), dir);
  ASSERT_EQ(sim.code, 0) << sim.err;
  EXPECT_FALSE(HasControlCharacters(sim.err)) << sim.err;
}

// On a terminal (script(1) gives the command a pseudo-terminal) the line is drawn, and --quiet stops it.
TEST(CliProgress, DrawnOnATerminalUnlessQuiet) {
  if (std::system("command -v script > /dev/null 2>&1") != 0) GTEST_SKIP() << "script(1) is not installed";
  const fs::path dir = FreshDir("cli_progress", "tty");
  auto on_terminal = [&](const std::string& arguments) {
    const fs::path log = dir / "typescript";
    const std::string inner = std::string(SELFCAL_BINARY) + " " + arguments;
    const std::string command = "cd " + std::string(SELFCAL_SOURCE_DIR) + " && script -qec '" + inner + "' " + log.string() +
                                " > /dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return ReadFile(log.string());
  };
  const std::string drawn = on_terminal("study --runs 3 --noise-px 0.2 --no-bound --no-opencv --out " + (dir / "a.json").string());
  EXPECT_NE(drawn.find("\rstudy runs ["), std::string::npos) << drawn;
  EXPECT_NE(drawn.find("3/3"), std::string::npos);
  EXPECT_NE(drawn.find(" left"), std::string::npos);
  const std::string quiet =
      on_terminal("study --runs 3 --noise-px 0.2 --no-bound --no-opencv --quiet --out " + (dir / "b.json").string());
  EXPECT_EQ(quiet.find("study runs ["), std::string::npos) << quiet;
}

TEST(CliHelp, ShowsDefaults) {
  std::string output;
  ASSERT_EQ(testing::RunSelfcal("calibrate --help", &output), 0) << output;
  EXPECT_NE(output.find("--method TEXT:{bundle,paper}=bundle"), std::string::npos) << output;
  EXPECT_NE(output.find("--out TEXT=out/calibration"), std::string::npos) << output;
  ASSERT_EQ(testing::RunSelfcal("study --help", &output), 0) << output;
  EXPECT_NE(output.find("--runs INT:INT in [1 - 100000]=200"), std::string::npos) << output;
}

TEST(CliHelp, SuggestsTheNearestCommandAndOption) {
  std::string output;
  EXPECT_EQ(testing::RunSelfcal("calibrat", &output), 2) << output;
  EXPECT_NE(output.find("unknown command `calibrat`; did you mean `calibrate`?"), std::string::npos) << output;
  EXPECT_EQ(output.find("A subcommand is required"), std::string::npos) << output;
  EXPECT_EQ(testing::RunSelfcal("calibrate --metod paper", &output), 2) << output;
  EXPECT_NE(output.find("selfcal calibrate: unknown option `--metod`; did you mean `--method`?"), std::string::npos)
      << output;
  EXPECT_EQ(testing::RunSelfcal("session discrad x", &output), 2) << output;
  EXPECT_NE(output.find("did you mean `discard`?"), std::string::npos) << output;
  EXPECT_EQ(testing::RunSelfcal("xyzzy", &output), 2) << output;
  EXPECT_NE(output.find("unknown command `xyzzy`; the commands are: calibrate"), std::string::npos) << output;
  // Beside --help too (CLI11 would answer the help first and exit 0), in both executables.
  EXPECT_EQ(testing::RunSelfcal("calibrat --help", &output), 2) << output;
  EXPECT_NE(output.find("unknown command `calibrat`; did you mean `calibrate`?"), std::string::npos) << output;
  EXPECT_EQ(testing::RunSelfcal("calibrate --metod paper --help", &output), 2) << output;
  EXPECT_NE(output.find("did you mean `--method`?"), std::string::npos) << output;
  EXPECT_EQ(testing::RunSelfcal("simulate --nois-px 1 --help", &output), 2) << output;
  EXPECT_NE(output.find("did you mean `--noise-px`?"), std::string::npos) << output;
}

TEST(CliMessages, FileTextIsEscapedBeforeItReachesTheTerminal) {
  const fs::path dir = FreshDir("cli_messages", "escape");
  // A double-quoted YAML scalar may spell control characters as escapes: the value quoted in the error
  // must not clear the screen.
  std::string robot = ReadFile(std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml");
  const size_t convention = robot.find("dh_convention: standard");
  ASSERT_NE(convention, std::string::npos);
  robot.replace(convention, 23, "dh_convention: \"\\e[2Jstandard\\0\"");
  WriteFile((dir / "robot.yaml").string(), robot);
  std::string output;
  EXPECT_EQ(testing::RunSelfcal("plan --robot " + (dir / "robot.yaml").string() + " --out " + (dir / "p.yaml").string(),
                                &output),
            2)
      << output;
  EXPECT_EQ(output.find('\x1b'), std::string::npos) << output;
  EXPECT_EQ(output.find('\0'), std::string::npos);
  EXPECT_NE(output.find("\\x1b[2J"), std::string::npos) << output;
}

}  // namespace
}  // namespace selfcal
