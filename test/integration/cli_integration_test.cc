#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/observations_file.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "sim/trajectory_generator.h"

#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

// Runs the selfcal binary with arguments; returns its exit code, output in *output.
using testing::RunSelfcal;

fs::path FreshDir(const std::string& name) { return testing::FreshDir("it", name); }

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(Cli, SimulateEndToEndThenCalibrateTheSameFileIsDeterministic) {
  const fs::path dir = FreshDir("simulate");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --out " + dir.string() + " --seed 3", &output), 0) << output;
  for (const char* file : {"observations.yaml", "truth.json", "report.json", "image_residuals.csv",
                           "calibrated_model.yaml", "comparison_with_truth.json"}) {
    EXPECT_TRUE(fs::exists(dir / file)) << file << "\n" << output;
  }
  const nlohmann::json first = ReadJson(dir / "report.json");
  // The default method is the kinematic bundle adjustment, started from the paper pipeline.
  EXPECT_EQ(first["method"], "bundle");
  EXPECT_EQ(first["verdict"], "accepted");
  EXPECT_EQ(first["methods"]["bundle"]["outcome"], "converged");
  EXPECT_EQ(first["methods"]["paper"]["outcome"], "success");
  EXPECT_EQ(first["version"], 3);
  EXPECT_TRUE(first["accepted"].get<bool>());
  // The calibrated model is a robot config selfcal reads back.
  EXPECT_TRUE(io::LoadRobotModel((dir / "calibrated_model.yaml").string()).ok());
  // P9/F9: the same observations and seed give the same numbers.
  const fs::path again = dir / "again";
  ASSERT_EQ(RunSelfcal("calibrate " + (dir / "observations.yaml").string() + " --seed 3 --out " + again.string(), &output), 0)
      << output;
  nlohmann::json second = ReadJson(again / "report.json");
  // Bit for bit, the bundle adjustment included: its parameter blocks sit in one buffer in a fixed
  // layout, so Ceres' address-ordered elimination does not depend on this process's heap.
  nlohmann::json a = first, b = second;
  for (nlohmann::json* j : {&a, &b}) {
    j->erase("timing");
    j->erase("input");
  }
  EXPECT_EQ(a.dump(), b.dump());
  EXPECT_EQ(testing::ReadFile((dir / "image_residuals.csv").string()),
            testing::ReadFile((again / "image_residuals.csv").string()));
  fs::remove_all(dir);
}

// --method bundle: the report's bundle section, the model written from the bundle; --method paper: the
// baseline alone. (The bundle's accuracy against the paper's is checked over several worlds in
// pipeline's bundle_stage_test, where one draw cannot decide.)
TEST(Cli, SimulateWithTheBundleMethodReportsTheBundleAndWritesItsModel) {
  const fs::path dir = FreshDir("bundle");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --method bundle --noise-px 0.2 --seed 5 --out " + dir.string(), &output), 0) << output;
  const nlohmann::json report = ReadJson(dir / "report.json");
  EXPECT_EQ(report["method"], "bundle");
  EXPECT_EQ(report["exit_code"], 0);
  const nlohmann::json& b = report["methods"]["bundle"];
  EXPECT_EQ(b["outcome"], "converged") << b.dump(2);
  EXPECT_EQ(b["start"], "paper_pipeline");
  EXPECT_FALSE(b["solver"]["termination"].get<std::string>().empty());
  EXPECT_GT(b["solver"]["iterations"].get<int>(), 0);
  EXPECT_LT(b["rms_reprojection_px"].get<double>(), 0.5);
  EXPECT_TRUE(b["removed_observations"].is_array());
  EXPECT_EQ(b["free"].size(), 24u);
  EXPECT_EQ(b["free"].size() + b["fixed"].size(), b["parameters"].size());
  for (const nlohmann::json& p : b["parameters"]) {
    const bool length = p.contains("value_m");
    EXPECT_TRUE(length || p.contains("value_rad")) << p.dump();
    const std::string sd = length ? "stddev_m" : "stddev_rad";
    ASSERT_TRUE(p.contains(sd)) << p.dump();
    EXPECT_EQ(p["free"].get<bool>(), !p[sd].is_null()) << p.dump();
  }
  EXPECT_GT(b["fx_stddev_px"].get<double>(), 0);
  EXPECT_EQ(b["verification"]["calibrated_model"]["num_ok"], 40);
  // The top level is the chosen method's answer.
  EXPECT_EQ(report["verification"], b["verification"]);
  EXPECT_EQ(report["fx_px"], b["fx_px"]);
  EXPECT_NE(output.find("kinematic bundle adjustment vs truth"), std::string::npos) << output;
  // Against the truth (this seed, deterministic): the verification relative poses, 10 mm off with the
  // nominal model, come within ~1 mm.
  const nlohmann::json comparison = ReadJson(dir / "comparison_with_truth.json");
  ASSERT_TRUE(comparison.contains("bundle"));
  const nlohmann::json& pose_mm = comparison["bundle"]["verification_pose_error_mean_mm"];
  EXPECT_LT(pose_mm["bundle"].get<double>(), 0.3 * pose_mm["nominal"].get<double>()) << pose_mm.dump();
  Result<io::CalibratedModel> model = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  EXPECT_NEAR(model->fx_px, b["fx_px"].get<double>(), 1e-6);
  // The baseline alone on the same file: no bundle section, the paper's outcome.
  const fs::path paper = dir / "paper";
  // It measures the check distances worse than the nominal model (at 0.2 px the factor method's model is
  // the weaker one), so the verdict refuses it, saying why, and writes no model.
  ASSERT_EQ(RunSelfcal("calibrate " + (dir / "observations.yaml").string() + " --method paper --out " + paper.string(),
                       &output), 6) << output;
  const nlohmann::json baseline = ReadJson(paper / "report.json");
  EXPECT_EQ(baseline["method"], "paper");
  EXPECT_EQ(baseline["verdict"], "rejected");
  ASSERT_EQ(baseline["reasons"].size(), 1u) << baseline["reasons"].dump();
  EXPECT_NE(baseline["reasons"][0].get<std::string>().find("worse than the robot it started from"), std::string::npos);
  EXPECT_FALSE(fs::exists(paper / "calibrated_model.yaml"));
  EXPECT_EQ(baseline["methods"]["paper"]["outcome"], "success");
  EXPECT_FALSE(baseline["methods"].contains("bundle"));
  EXPECT_EQ(baseline["verification"], baseline["methods"]["paper"]["verification"]);
  EXPECT_EQ(RunSelfcal("calibrate " + (dir / "observations.yaml").string() + " --method nonsense --out " + paper.string(),
                       &output), 2) << output;
  fs::remove_all(dir);
}

// A flat dot sheet: the paper pipeline is degenerate (exit 3, no model), the bundle adjustment is not.
TEST(Cli, FlatSheetIsDegenerateForThePaperMethodAndCalibratesWithTheBundle) {
  const fs::path dir = FreshDir("flat");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --flat-sheet --out " + dir.string(), &output), 0) << output;
  const nlohmann::json report = ReadJson(dir / "report.json");
  EXPECT_EQ(report["methods"]["paper"]["outcome"], "degenerate");
  EXPECT_EQ(report["methods"]["bundle"]["outcome"], "converged");
  EXPECT_EQ(report["methods"]["bundle"]["start"], "nominal");
  EXPECT_EQ(report["verdict"], "accepted");
  EXPECT_TRUE(fs::exists(dir / "calibrated_model.yaml"));
  const fs::path paper = dir / "paper";
  EXPECT_EQ(RunSelfcal("calibrate " + (dir / "observations.yaml").string() + " --method paper --out " + paper.string(),
                       &output), 3) << output;
  EXPECT_FALSE(fs::exists(paper / "calibrated_model.yaml"));
  fs::remove_all(dir);
}

TEST(Cli, ConfigErrorsExitWithCode2AndNameTheFile) {
  const fs::path dir = FreshDir("bad");
  std::string output;
  EXPECT_EQ(RunSelfcal("calibrate " + (dir / "missing.yaml").string() + " --out " + dir.string(), &output), 2) << output;
  EXPECT_NE(output.find("missing.yaml"), std::string::npos) << output;
  const fs::path bad = dir / "bad.yaml";
  std::ofstream(bad) << "format: selfcal-observations\nversion: 1\nposez: []\n";
  EXPECT_EQ(RunSelfcal("calibrate " + bad.string() + " --out " + dir.string(), &output), 2) << output;
  EXPECT_NE(output.find("bad.yaml"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("calibrate", &output), 2) << output;                  // missing argument
  EXPECT_EQ(RunSelfcal("no-such-command", &output), 2) << output;
  EXPECT_EQ(RunSelfcal("study --runs 0", &output), 2) << output;             // out of range
  fs::remove_all(dir);
}

TEST(Cli, DegenerateDataExitsWithCode3AndWritesNoModel) {
  // Keep only four identification poses: three pose measurements are too few.
  const fs::path dir = FreshDir("degenerate");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --out " + dir.string(), &output), 0) << output;
  Result<ObservationSet> obs = io::LoadObservations((dir / "observations.yaml").string());
  ASSERT_TRUE(obs.ok()) << obs.status().ToString();
  ObservationSet few = *obs;
  few.poses.erase(few.poses.begin() + 4, few.poses.begin() + 15);
  const fs::path few_path = dir / "few.yaml";
  ASSERT_TRUE(io::SaveObservations(few, few_path.string()).ok());
  const fs::path out = dir / "few_out";
  EXPECT_EQ(RunSelfcal("calibrate " + few_path.string() + " --out " + out.string(), &output), 3) << output;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  EXPECT_FALSE(fs::exists(out / "calibrated_model.yaml"));
  EXPECT_FALSE(ReadJson(out / "report.json")["accepted"].get<bool>());
  fs::remove_all(dir);
}

TEST(Cli, ShippedInitialTrajectoryIsTheGeneratorsOutput) {
  Result<RobotModel> puma = io::LoadRobotModel(std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml");
  ASSERT_TRUE(puma.ok()) << puma.status().ToString();
  Result<std::vector<Eigen::VectorXd>> shipped =
      io::LoadTrajectory(std::string(SELFCAL_SOURCE_DIR) + "/config/trajectories/initial_puma560.yaml", 6);
  ASSERT_TRUE(shipped.ok()) << shipped.status().ToString();
  const sim::GeneratedTrajectory generated = sim::MakeArcTrajectory(*puma, sim::ArcTrajectoryOptions());
  ASSERT_TRUE(generated.ok) << generated.message;
  ASSERT_EQ(shipped->size(), generated.joints.size());
  for (size_t i = 0; i < generated.joints.size(); ++i) {
    EXPECT_LT(((*shipped)[i] - generated.joints[i]).cwiseAbs().maxCoeff(), 1e-9) << "pose " << i;
  }
}

// The model is not PUMA-shaped: a UR5e-class arm (axes 2, 3, 4 parallel) end to end, noise-free, where
// calibration must beat the nominal model on held-out distances.
TEST(Cli, Ur5eSimulationBeatsItsNominalModel) {
  const fs::path dir = FreshDir("ur5e");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --robot config/robots/ur5e.yaml --trajectory config/trajectories/initial_ur5e.yaml "
                       "--noise-px 0 --out " + dir.string(), &output), 0) << output;
  const nlohmann::json report = ReadJson(dir / "report.json");
  const nlohmann::json& paper = report["methods"]["paper"];
  EXPECT_EQ(paper["identifiability"]["identifiable"], 24);
  const double nominal = paper["verification"]["nominal_model"]["rms_error_m"];
  const double calibrated = paper["verification"]["calibrated_model"]["rms_error_m"];
  EXPECT_LT(calibrated, 0.5 * nominal) << output;
  // The bundle adjustment (the default method) on the same data, noise-free: exact.
  EXPECT_EQ(report["methods"]["bundle"]["outcome"], "converged") << output;
  EXPECT_LT(report["verification"]["calibrated_model"]["max_error_m"].get<double>(), 1e-9) << output;
  fs::remove_all(dir);
}

TEST(Cli, IdentifiabilityNamesTheFixedParameters) {
  std::string output;
  ASSERT_EQ(RunSelfcal("identifiability", &output), 0) << output;
  EXPECT_NE(output.find("metric relative poses"), std::string::npos) << output;
  EXPECT_NE(output.find("base.tx"), std::string::npos) << output;
  EXPECT_NE(output.find("j1.theta"), std::string::npos) << output;
}

}  // namespace
}  // namespace selfcal

namespace selfcal {
namespace {

// selfcal plan: the shipped arc passes --check (robot-level: it records no scene), the planned file
// records its scene and passes every check, and the same seed writes the same plan byte for byte.
TEST(Cli, PlanCheckAcceptsTheArcAndThePlannedFile) {
  const fs::path dir = FreshDir("plan");
  auto read_file = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  std::string output;
  EXPECT_EQ(RunSelfcal("plan --check config/trajectories/initial_puma560.yaml", &output), 0) << output;
  EXPECT_NE(output.find("no `planned_for` block"), std::string::npos) << output;
  const std::string a = (dir / "a.yaml").string(), b = (dir / "b.yaml").string();
  ASSERT_EQ(RunSelfcal("plan --criterion d-optimal --seed 4 --out " + a, &output), 0) << output;
  ASSERT_EQ(RunSelfcal("plan --criterion d-optimal --seed 4 --out " + b, &output), 0) << output;
  EXPECT_EQ(read_file(a), read_file(b));
  EXPECT_EQ(RunSelfcal("plan --check " + a, &output), 0) << output;
  EXPECT_NE(output.find("plan ok"), std::string::npos) << output;
  EXPECT_NE(output.find("image motion per move"), std::string::npos) << output;
  EXPECT_NE(output.find("predicted std at 0.2 px"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("plan --criterion best --out " + a, &output), 2) << output;
  // The defaults follow the robot: start and scene from initial_ur5e.yaml.
  // --force: a.yaml is the plan written above.
  EXPECT_EQ(RunSelfcal("plan --robot config/robots/ur5e.yaml --criterion a-optimal --force --out " + a, &output), 0)
      << output;
  EXPECT_NE(output.find("initial_ur5e.yaml"), std::string::npos) << output;
}

// The problem lines of `plan --check` ("  PROBLEM issue: ...") or of run's preflight ("  issue: ...").
std::vector<std::string> ProblemLines(const std::string& output, const std::string& prefix) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  bool refused = false;
  for (std::string line; std::getline(in, line);) {
    if (line.find("preflight refused the plan:") != std::string::npos) refused = true;
    if (prefix.empty() ? refused && line.rfind("  ", 0) == 0 : line.rfind(prefix, 0) == 0) {
      lines.push_back(line.substr(prefix.empty() ? 2 : prefix.size()));
    }
  }
  return lines;
}

// One check: `plan --check` and run's preflight give the same verdict in the same words on every shipped
// trajectory; every shipped trajectory passes for its own robot (the robot its name ends with), and is
// refused for the next shipped robot in both paths as a usage error (exit 2) naming both robots.
TEST(Cli, PlanCheckAndRunPreflightAgreeOnEveryShippedTrajectory) {
  const fs::path dir = FreshDir("agree");
  const fs::path trajectories = fs::path(SELFCAL_SOURCE_DIR) / "config" / "trajectories";
  const std::vector<std::string> robots = {"puma560", "ur5e", "panda", "irb140"};
  int files = 0;
  std::set<std::string> robots_with_a_trajectory;
  for (const fs::directory_entry& e : fs::directory_iterator(trajectories)) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    const std::string name = e.path().stem().string();
    std::string own;
    for (const std::string& robot : robots) {
      if (name.size() > robot.size() && name.compare(name.size() - robot.size() - 1, std::string::npos, "_" + robot) == 0) {
        own = robot;
      }
    }
    ASSERT_FALSE(own.empty()) << name << ": a shipped trajectory's name ends with its robot";
    robots_with_a_trajectory.insert(own);
    const size_t at = std::find(robots.begin(), robots.end(), own) - robots.begin();
    for (const std::string& robot : {own, robots[(at + 1) % robots.size()]}) {
      const std::string config = "config/robots/" + robot + ".yaml";
      std::string check_out, run_out;
      const int check = RunSelfcal("plan --robot " + config + " --check " + e.path().string(), &check_out);
      const int run = RunSelfcal("run --backend sim --camera sim --dry-run --robot-config " + config + " --session " +
                                     (dir / (name + "-" + robot)).string() + " --plan " + e.path().string(),
                                 &run_out);
      EXPECT_EQ(check, run) << name << " on " << robot << "\n" << check_out << "\n" << run_out;
      EXPECT_EQ(ProblemLines(check_out, "  PROBLEM "), ProblemLines(run_out, "")) << name << " on " << robot;
      if (robot == own) {
        EXPECT_EQ(check, 0) << name << "\n" << check_out;
        continue;
      }
      EXPECT_EQ(check, 2) << name << " on " << robot << "\n" << check_out;
      for (const std::string* out : {&check_out, &run_out}) {
        EXPECT_NE(out->find("is for robot `" + own + "`"), std::string::npos) << *out;
        EXPECT_NE(out->find("is robot `" + robot + "`"), std::string::npos) << *out;
      }
    }
  }
  EXPECT_EQ(robots_with_a_trajectory.size(), robots.size()) << "every shipped robot has a trajectory";
  EXPECT_GE(files, 12);
}

}  // namespace
}  // namespace selfcal

namespace selfcal {
namespace {

// selfcal simulate (default): simulated arm + rendered camera through a session, calibrated offline from
// it; the bundle's held-out 3-D error must beat the nominal model's, and the session must be complete.
TEST(CliSession, SimulateRunsASessionEndToEndAndBeatsTheNominalModel) {
  const fs::path dir = FreshDir("simulate_session");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --out " + dir.string() + " --seed 2", &output), 0) << output;
  EXPECT_TRUE(fs::exists(dir / "session" / "session.json"));
  EXPECT_TRUE(fs::exists(dir / "calibrated_model.yaml"));
  const nlohmann::json comparison = ReadJson(dir / "comparison_with_truth.json");
  const double nominal = comparison["bundle"]["error3d_rms_mm"]["nominal"].get<double>();
  const double bundle = comparison["bundle"]["error3d_rms_mm"]["bundle"].get<double>();
  EXPECT_LT(bundle, 0.25 * nominal) << output;
  // A second simulate into the same folder is refused (its files are there) unless --force, and then makes a
  // new session, never overwriting the first (C10).
  EXPECT_EQ(RunSelfcal("simulate --out " + dir.string() + " --seed 2", &output), 2) << output;
  EXPECT_NE(output.find("--force"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "session-2"));
  ASSERT_EQ(RunSelfcal("simulate --out " + dir.string() + " --seed 2 --force", &output), 0) << output;
  EXPECT_TRUE(fs::exists(dir / "session-2" / "session.json"));
}

TEST(CliSession, RunRefusesAnExistingSessionAndAChangedConfigOnResume) {  // C9, C10
  const fs::path dir = FreshDir("run_refusals");
  const std::string session = (dir / "s").string();
  std::string output;
  ASSERT_EQ(RunSelfcal("run --session " + session + " --seed 3", &output), 0) << output;
  EXPECT_EQ(RunSelfcal("run --session " + session + " --seed 3", &output), 2) << output;
  EXPECT_NE(output.find(session), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("run --resume --session " + session + " --seed 4", &output), 2) << output;
  EXPECT_NE(output.find("run.json"), std::string::npos) << output;
  // Resuming a finished session with the same inputs has nothing left to do.
  EXPECT_EQ(RunSelfcal("run --resume --session " + session + " --seed 3", &output), 0) << output;
}

TEST(CliSession, HardwareFaultExitsFourAndResumeFinishesTheSession) {  // R9, exit codes
  const fs::path dir = FreshDir("run_fault");
  const std::string session = (dir / "s").string();
  std::string output;
  EXPECT_EQ(RunSelfcal("run --session " + session + " --seed 3 --fault-protective-stop-move 3", &output), 4) << output;
  EXPECT_NE(output.find("protective_stop"), std::string::npos) << output;
  EXPECT_NE(output.find("HALTED"), std::string::npos) << output;
  // Resuming needs the same inputs (the fault flags are inputs), so the operator resumes with them; the
  // restarted simulated arm counts its moves afresh, so move #3 stops again: a halt is never silently
  // skipped. Without the fault flag the inputs differ and resume is refused.
  EXPECT_EQ(RunSelfcal("run --resume --session " + session + " --seed 3", &output), 2) << output;
  ASSERT_EQ(RunSelfcal("calibrate " + session + " --out " + (dir / "cal").string(), &output), 3) << output;
}

TEST(CliSession, DryRunPrintsThePreviewAndCreatesNothing) {  // R1, F8
  const fs::path dir = FreshDir("run_dry");
  const std::string session = (dir / "sessions" / "s").string();
  std::string output;
  ASSERT_EQ(RunSelfcal("run --dry-run --session " + session + " --seed 3", &output), 0) << output;
  EXPECT_NE(output.find("dry run: nothing moved"), std::string::npos) << output;
  EXPECT_NE(output.find("25 moves"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "sessions")) << output;  // neither the session nor its parent folder
  // The real run that follows is not refused.
  ASSERT_EQ(RunSelfcal("run --session " + session + " --seed 3", &output), 0) << output;
  EXPECT_TRUE(fs::exists(fs::path(session) / "session.json"));
}

// `run --robot` means the robot config, as in every other command; a backend name there is --backend's old
// spelling, still taken with a note; said twice (with --backend or --robot-config) it is refused before anything.
TEST(CliSession, RunRobotIsTheConfigAndTheOldBackendSpellingIsStillTaken) {
  const fs::path dir = FreshDir("run_robot_word");
  const std::string session = (dir / "s").string();
  const std::string puma = std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml";
  std::string output;
  ASSERT_EQ(RunSelfcal("run --dry-run --robot sim --camera sim --session " + session + " --seed 3", &output), 0) << output;
  EXPECT_NE(output.find("--robot sim is the old spelling of --backend sim"), std::string::npos) << output;
  EXPECT_NE(output.find("dry run: nothing moved"), std::string::npos) << output;
  ASSERT_EQ(RunSelfcal("run --dry-run --robot " + puma + " --backend sim --camera sim --session " + session + " --seed 3",
                       &output), 0) << output;
  EXPECT_EQ(output.find("old spelling"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("run --dry-run --robot sim --backend network --session " + session, &output), 2) << output;
  EXPECT_NE(output.find("both name the backend"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("run --dry-run --robot " + puma + " --robot-config " + puma + " --session " + session, &output), 2)
      << output;
  EXPECT_NE(output.find("both name the robot config"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(session));
}

// selfcal name-dots on a recorded frame: the annotated PNG, a setup that `run --setup` accepts with the
// reference identifier, and a yardstick id that was not detected refused naming it.
TEST(CliNameDots, NamesARecordedFrameWritesThePngAndASetupThatRunAccepts) {
  const fs::path dir = FreshDir("name_dots");
  const std::string frame = std::string(SELFCAL_SOURCE_DIR) + "/test/data/sequences/puma_arc_clean/frame_000000.png";
  const std::string setup = (dir / "setup.json").string();
  const std::string png = (dir / "named.png").string();
  std::string output;
  // A bad yardstick (an end that is not a detected dot, both ends one dot, a length no two dots have) is refused
  // before anything is written: neither the setup nor the PNG (issue 36: the PNG was written first).
  for (const char* bad : {"3,9999 --length-mm 200", "3,3 --length-mm 200", "3,10 --length-mm 0.5",
                          "3,10 --length-mm 100001"}) {
    EXPECT_EQ(RunSelfcal("name-dots --image " + frame + " --setup " + setup + " --out " + png +
                             " --fx-px 1000 --pixel-noise-px 0.02 --yardstick " + bad, &output), 2)
        << bad << "\n" << output;
    EXPECT_FALSE(fs::exists(setup)) << bad;
    EXPECT_FALSE(fs::exists(png)) << bad;
  }
  EXPECT_EQ(RunSelfcal("name-dots --image " + frame + " --setup " + setup + " --out " + png +
                           " --fx-px 1000 --pixel-noise-px 0.02 --yardstick 3,9999 --length-mm 200", &output), 2);
  EXPECT_NE(output.find("dot 9999 is not a named dot of this frame"), std::string::npos) << output;
  EXPECT_NE(output.find("nothing written"), std::string::npos) << output;
  ASSERT_EQ(RunSelfcal("name-dots --image " + frame + " --setup " + setup + " --out " + png +
                           " --fx-px 1000 --pixel-noise-px 0.02 --yardstick 3,10 --length-mm 200", &output), 0)
      << output;
  std::ifstream png_in(png, std::ios::binary);
  std::string magic(8, '\0');
  png_in.read(&magic[0], 8);
  EXPECT_EQ(magic, std::string("\x89PNG\r\n\x1a\n", 8));
  const nlohmann::json written = ReadJson(setup);
  EXPECT_EQ(written["version"], 1);
  ASSERT_EQ(written["yardsticks"].size(), 1u);
  EXPECT_EQ(written["yardsticks"][0]["dot_a"], 3);
  EXPECT_EQ(written["yardsticks"][0]["dot_b"], 10);
  EXPECT_DOUBLE_EQ(written["yardsticks"][0]["length_m"].get<double>(), 0.2);
  // Every reference dot is a row of the printed table (id u v area).
  ASSERT_GT(written["reference_dots"].size(), 10u);
  for (const nlohmann::json& d : written["reference_dots"]) {
    char row[64];
    std::snprintf(row, sizeof(row), "%8d %10.2f %10.2f", d["id"].get<int>(), d["u_px"].get<double>(), d["v_px"].get<double>());
    EXPECT_NE(output.find(row), std::string::npos) << row;
  }
  // An update keeps the yardstick unless a new one is given.
  ASSERT_EQ(RunSelfcal("name-dots --image " + frame + " --setup " + setup + " --out " + png + " --force", &output), 0)
      << output;
  EXPECT_EQ(ReadJson(setup)["yardsticks"], written["yardsticks"]);
  // run takes it with the reference identifier; it only stops at the camera this machine does not have.
  const fs::path joints = dir / "joints.txt";
  std::ofstream(joints) << "0 0 0 0 0 0\n";
  const std::string run = "run --backend manual --camera v4l2 --device " + (dir / "no-video").string() + " --setup " +
                          setup + " --identify reference --session " + (dir / "s").string();
  EXPECT_EQ(RunSelfcal(run + " < " + joints.string(), &output), 4) << output;
  EXPECT_NE(output.find("opening the camera"), std::string::npos) << output;
  // Without reference dots the reference identifier is refused before anything moves.
  nlohmann::json bare = written;
  bare.erase("reference_dots");
  std::ofstream(dir / "bare.json") << bare.dump(2);
  EXPECT_EQ(RunSelfcal("run --backend manual --camera v4l2 --setup " + (dir / "bare.json").string() +
                           " --identify reference --session " + (dir / "s2").string() + " < " + joints.string(), &output),
            2)
      << output;
  EXPECT_NE(output.find("name-dots"), std::string::npos) << output;
}

}  // namespace
}  // namespace selfcal
