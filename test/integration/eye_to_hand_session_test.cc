// The simulated eye-to-hand cell end to end, as a user runs it (docs/planning.md, docs/session-format.md):
// `selfcal plan --configuration eye_to_hand` chooses poses that keep the flange's plate in the fixed
// camera's view, `selfcal run --backend sim --camera sim --configuration eye_to_hand` records every pose with
// every dot named, `selfcal audit` scores the names against the hidden truth (none wrong), the session
// records its configuration; `run --resume` in the other configuration is refused with nothing written.
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"
#include "support/temp_files.h"
#include "support/tree_state.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::RunSelfcal;

using testing::Contains;

class EyeToHandSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(testing::FreshDir("eye_to_hand", "session"));
    plan_code_ = RunSelfcal("plan --configuration eye_to_hand --robot config/robots/puma560.yaml --pool 100 --out " +
                                (*root_ / "plan.yaml").string(),
                            &plan_output_);
    if (plan_code_ != 0) return;
    run_code_ = RunSelfcal("run --backend sim --camera sim --configuration eye_to_hand --live-view off --seed 3 --plan " +
                               (*root_ / "plan.yaml").string() + " --session " + (*root_ / "s").string(),
                           &run_output_);
  }
  void SetUp() override {
    ASSERT_EQ(plan_code_, 0) << plan_output_;
    ASSERT_EQ(run_code_, 0) << run_output_;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static fs::path* root_;
  static int plan_code_, run_code_;
  static std::string plan_output_, run_output_;
};

fs::path* EyeToHandSessionTest::root_ = nullptr;
int EyeToHandSessionTest::plan_code_ = -1;
int EyeToHandSessionTest::run_code_ = -1;
std::string EyeToHandSessionTest::plan_output_, EyeToHandSessionTest::run_output_;

TEST_F(EyeToHandSessionTest, PlanRecordsItsConfigurationAndPassesItsCheck) {
  const std::string plan = ReadFile((*root_ / "plan.yaml").string());
  EXPECT_TRUE(Contains(plan, "configuration: eye_to_hand")) << plan.substr(0, 2000);
  EXPECT_TRUE(Contains(plan, "base_from_cam:"));
  std::string output;
  EXPECT_EQ(RunSelfcal("plan --robot config/robots/puma560.yaml --check " + (*root_ / "plan.yaml").string(), &output), 0)
      << output;
  EXPECT_TRUE(Contains(output, "configuration eye_to_hand")) << output;
  EXPECT_TRUE(Contains(output, "plan ok")) << output;
}

TEST_F(EyeToHandSessionTest, EveryPoseRecordedAndNoIdentityWrong) {
  EXPECT_TRUE(Contains(run_output_, "configuration eye_to_hand")) << run_output_;
  const nlohmann::json manifest = nlohmann::json::parse(ReadFile((*root_ / "s" / "session.json").string()));
  EXPECT_EQ(manifest["configuration"], "eye_to_hand");
  const nlohmann::json setup = nlohmann::json::parse(ReadFile((*root_ / "s" / "inputs" / "setup.json").string()));
  EXPECT_EQ(setup["configuration"], "eye_to_hand");
  ASSERT_TRUE(setup.contains("base_from_cam"));
  std::string output;
  const fs::path audit = *root_ / "audit.json";
  ASSERT_EQ(RunSelfcal("audit " + (*root_ / "s").string() + " --json " + audit.string(), &output), 0) << output;
  EXPECT_TRUE(Contains(output, "eye_to_hand: 25/25 samples accepted")) << output;
  const nlohmann::json identities = nlohmann::json::parse(ReadFile(audit.string()))["identities"];
  EXPECT_EQ(identities["configuration"], "eye_to_hand");
  EXPECT_EQ(identities["poses_planned"], 25);
  EXPECT_EQ(identities["samples_accepted"], 25);
  EXPECT_EQ(identities["wrong_total"], 0);
  // The plate's 16 dots are in view at every pose and the session named nearly all of them.
  EXPECT_GE(identities["in_view_per_sample"]["min"].get<int>(), 16);
  EXPECT_GE(identities["named_of_in_view"]["mean"].get<double>(), 0.9);
}

TEST_F(EyeToHandSessionTest, ResumeInTheOtherConfigurationIsRefusedAndChangesNothing) {
  const fs::path session = *root_ / "s";
  const auto before = testing::TreeState(session);
  std::string output;
  const int code = RunSelfcal("run --backend sim --camera sim --configuration eye_in_hand --live-view off --seed 3 --plan " +
                                  (*root_ / "plan.yaml").string() + " --session " + session.string() + " --resume",
                              &output);
  EXPECT_EQ(code, 2) << output;
  EXPECT_TRUE(Contains(output, session.string())) << output;
  EXPECT_TRUE(Contains(output, "eye_to_hand")) << output;
  EXPECT_TRUE(Contains(output, "eye_in_hand")) << output;
  EXPECT_EQ(testing::TreeState(session), before);
}

// `selfcal simulate --configuration eye_to_hand` on the plan: the same session, calibrated offline from it and
// compared with the hidden truth. Accepted (exit 0); every free parameter of the bundle within 5 of its
// reported standard deviations of the truth; the fixed camera within 4 reported sigmas of its translation;
// f_x within 4 sigma; no wrong identity. 5, not 4: the rendered plate is seen at up to 55 deg, and the
// centroid bias of its tilted dots is not in the pixel noise the sigmas come from. Measured, errors over
// reported sigmas, RMS over the 24 free parameters: 1.72 / 1.06 / 1.15 at seeds 3 / 4 / 5, largest 4.06
// (cam.ry, seed 3, with cam.tx at 3.96 and j2.theta at 3.75: one direction); the eye-in-hand cell gives
// 0.87 / 0.95, largest 2.18.
TEST_F(EyeToHandSessionTest, SimulateCalibratesTheSessionWithinItsReportedSigmas) {
  const fs::path out = *root_ / "simulate";
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --configuration eye_to_hand --live-view off --no-html --seed 3 --trajectory " +
                           (*root_ / "plan.yaml").string() + " --out " + out.string(),
                       &output),
            0)
      << output;
  const nlohmann::json comparison = nlohmann::json::parse(ReadFile((out / "comparison_with_truth.json").string()));
  const nlohmann::json& bundle = comparison["bundle"];
  ASSERT_FALSE(bundle["parameters"].empty()) << output;
  double cam_sigma_mm2 = 0;
  for (const nlohmann::json& p : bundle["parameters"]) {
    const std::string name = p["name"];
    const bool length = p.contains("error_mm");
    const double error = length ? p["error_mm"].get<double>() : p["error_deg"].get<double>();
    const double sigma = length ? p["stddev_mm"].get<double>() : p["stddev_deg"].get<double>();
    EXPECT_LE(std::abs(error), 5 * sigma) << name << "\n" << output;
    if (name.rfind("cam.t", 0) == 0) cam_sigma_mm2 += sigma * sigma;
  }
  EXPECT_LE(std::abs(bundle["fx_bundle_px"].get<double>() - bundle["fx_true_px"].get<double>()),
            4 * bundle["fx_stddev_px"].get<double>());
  ASSERT_TRUE(bundle["base_from_cam"].is_object()) << output;
  EXPECT_LE(bundle["base_from_cam"]["error_mm"].get<double>(), 4 * std::sqrt(cam_sigma_mm2) + 1e-3) << output;
  EXPECT_EQ(comparison["identities"]["samples_accepted"], 25);
  EXPECT_EQ(comparison["identities"]["wrong_total"], 0);
}

// The README's three commands as written (the planner's default pool, the simulated arm and camera by
// default): accepted. With that plan the camera's start from the images leaves the plate's dots
// untriangulable, and the bundle must start again from the robot description's mount rather than end
// scale_unresolved (exit 3) on a good session.
TEST(EyeToHandReadme, PlanRunCalibrateWithTheDefaultsIsAccepted) {
  const fs::path root = testing::FreshDir("eye_to_hand", "readme");
  const std::string plan = (root / "e2h-plan.yaml").string(), session = (root / "e2h").string();
  std::string output;
  ASSERT_EQ(RunSelfcal("plan --configuration eye_to_hand --robot config/robots/puma560.yaml --out " + plan, &output), 0)
      << output;
  ASSERT_EQ(RunSelfcal("run --configuration eye_to_hand --live-view off --plan " + plan + " --session " + session +
                           " --seed 3",
                       &output),
            0)
      << output;
  EXPECT_EQ(RunSelfcal("calibrate " + session + " --out " + (root / "e2h-calibration").string(), &output), 0) << output;
  EXPECT_TRUE(Contains(output, "accepted")) << output;
  fs::remove_all(root);
}

}  // namespace
}  // namespace selfcal
