#include "report/calibration_report.h"

#include <iomanip>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "report/literature.h"
#include "report/study_report.h"
#include "support/sim_worlds.h"

namespace selfcal::report {
namespace {

// Every key of the document, with its path, for the key-style checks.
void CollectKeys(const nlohmann::json& j, const std::string& path, std::vector<std::string>* keys) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      keys->push_back(path + "/" + key);
      CollectKeys(value, path + "/" + key, keys);
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) CollectKeys(j[i], path + "/" + std::to_string(i), keys);
  }
}

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

class CalibrationReportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new sim::SimResult(testing::PumaArcWorld(0.2, 2, 2));
    report_ = new calibration::CalibrationReport(calibration::Calibrate(world_->observations, {}));
  }
  static void TearDownTestSuite() {
    delete report_;
    delete world_;
  }
  static sim::SimResult* world_;
  static calibration::CalibrationReport* report_;
};
sim::SimResult* CalibrationReportTest::world_ = nullptr;
calibration::CalibrationReport* CalibrationReportTest::report_ = nullptr;

TEST_F(CalibrationReportTest, TopLevelCarriesTheChosenMethodsFigures) {
  ASSERT_TRUE(report_->accepted()) << report_->message;
  const nlohmann::json j = CalibrationReportJson(world_->observations, *report_, {{"observations", "o.yaml", "ab", "", "", ""}, 0, {}});
  EXPECT_EQ(j["format"], kCalibrationReportFormat);
  EXPECT_EQ(j["version"], 3);
  EXPECT_EQ(j["method"], "bundle");
  EXPECT_EQ(j["verdict"], "accepted");
  EXPECT_EQ(j["accepted"], true);
  EXPECT_EQ(j["fx_px"], j["methods"]["bundle"]["fx_px"]);
  EXPECT_EQ(j["verification"], j["methods"]["bundle"]["verification"]);
  EXPECT_DOUBLE_EQ(j["verification"]["calibrated_model"]["rms_error_m"].get<double>(),
                   report_->bundle->verification.rms_error_m);
  EXPECT_NE(j["verification"], j["methods"]["paper"]["verification"]);
  EXPECT_EQ(j["input"]["sha256"], "ab");
  EXPECT_TRUE(j["session"].is_null());
}

// methods.bundle.intrinsics: every intrinsic by name with its value, whether it was estimated (the default:
// f_x alone) and its std, null when held; the values are the bundle's, the f_x std its covariance's.
TEST_F(CalibrationReportTest, BundleIntrinsicsNameEveryIntrinsicWithItsEstimateFlagAndStd) {
  const nlohmann::json j = CalibrationReportJson(world_->observations, *report_, {});
  const nlohmann::json& in = j["methods"]["bundle"]["intrinsics"];
  const bundle::BundleReport& b = report_->bundle->bundle;
  ASSERT_EQ(in.size(), static_cast<size_t>(kNumIntrinsics)) << in.dump();
  for (int k = 0; k < kNumIntrinsics; ++k) {
    const std::string unit = k == kFx || k == kCx || k == kCy ? "_px" : "";
    const nlohmann::json& e = in.at(IntrinsicName(k));
    EXPECT_EQ(e.at("estimated").get<bool>(), k == kFx) << IntrinsicName(k);
    EXPECT_EQ(e.at("value" + unit).get<double>(), b.intrinsics[k]) << IntrinsicName(k);
    EXPECT_EQ(e.at("stddev" + unit).is_null(), k != kFx) << IntrinsicName(k);
  }
  EXPECT_EQ(in["fx"]["value_px"].get<double>(), j["fx_px"].get<double>());
  EXPECT_EQ(in["fx"]["stddev_px"].get<double>(), b.fx_stddev);
  EXPECT_EQ(in["cx"]["value_px"].get<double>(), world_->observations.camera.cx_px);  // held: as observed
  EXPECT_TRUE(j["input"]["camera_file"].is_null());
  const nlohmann::json named = CalibrationReportJson(world_->observations, *report_,
                                                     {{"observations", "o.yaml", "ab", "cam.xml", "cd", "Camera"}, 0, {}});
  EXPECT_EQ(named["input"]["camera_file"]["path"], "cam.xml");
  EXPECT_EQ(named["input"]["camera_file"]["sha256"], "cd");
  EXPECT_EQ(named["input"]["camera_file"]["camera_name"], "Camera");
}

// The summary names the estimated intrinsics and gives each one beside f_x with its std.
TEST(CalibrationReport, SummaryNamesTheEstimatedIntrinsics) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 2, 2);
  calibration::CalibrateOptions options;
  options.bundle.bundle.intrinsics[kCx] = options.bundle.bundle.intrinsics[kCy] = true;
  const calibration::CalibrationReport report = calibration::Calibrate(world.observations, options);
  ASSERT_TRUE(report.accepted()) << report.message;
  std::ostringstream text;
  PrintCalibrationSummary(world.observations, report, text);
  EXPECT_NE(text.str().find("free kinematic parameters + f_x + cx + cy,"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("  intrinsics: cx = "), std::string::npos) << text.str();
  const nlohmann::json j = CalibrationReportJson(world.observations, report, {});
  EXPECT_TRUE(j["methods"]["bundle"]["intrinsics"]["cy"]["estimated"].get<bool>());
  EXPECT_GT(j["methods"]["bundle"]["intrinsics"]["cy"]["stddev_px"].get<double>(), 0);
}

// A held f_x is stated as held, never with a nan std: the summary says `(held)`, report.json gives its value
// with estimated false and a null std.
TEST(CalibrationReport, AHeldFocalLengthIsStatedAsHeld) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 2, 2);
  calibration::CalibrateOptions options;
  options.bundle.bundle.held_parameters = {"fx"};
  const calibration::CalibrationReport report = calibration::Calibrate(world.observations, options);
  ASSERT_TRUE(report.bundle.has_value());
  std::ostringstream text;
  PrintCalibrationSummary(world.observations, report, text);
  EXPECT_EQ(text.str().find("nan"), std::string::npos) << text.str();
  std::ostringstream fx;
  fx << std::fixed << std::setprecision(3) << world.observations.camera.fx_px;
  EXPECT_NE(text.str().find("f_x = " + fx.str() + " px (held)"), std::string::npos) << text.str();
  const nlohmann::json j = CalibrationReportJson(world.observations, report, {});
  const nlohmann::json& in = j["methods"]["bundle"]["intrinsics"]["fx"];
  EXPECT_FALSE(in["estimated"].get<bool>());
  EXPECT_TRUE(in["stddev_px"].is_null());
  EXPECT_EQ(in["value_px"].get<double>(), world.observations.camera.fx_px);
}

// One key style: SI values with the unit in the key; no mm or degree keys anywhere in report.json.
TEST_F(CalibrationReportTest, EveryKeyIsSi) {
  const nlohmann::json j = CalibrationReportJson(world_->observations, *report_, {});
  std::vector<std::string> keys;
  CollectKeys(j, "", &keys);
  ASSERT_GT(keys.size(), 100u);
  for (const std::string& k : keys) {
    EXPECT_FALSE(EndsWith(k, "_mm") || EndsWith(k, "_deg") || k.find("_mm/") != std::string::npos) << k;
  }
}

// Both method sections have the same shape at their top.
TEST_F(CalibrationReportTest, MethodSectionsAreSymmetric) {
  const nlohmann::json j = CalibrationReportJson(world_->observations, *report_, {});
  for (const char* method : {"paper", "bundle"}) {
    for (const char* key : {"description", "verdict", "outcome", "message", "fx_px", "parameters", "verification",
                            "predicted_3d_error"}) {
      EXPECT_TRUE(j["methods"][method].contains(key)) << method << "." << key;
    }
  }
}

// A scene without known distances has no distance figures: they are absent (null), not 0.
TEST(CalibrationReport, AbsentFiguresAreNullNotZero) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 1, 1);
  world.observations.check_distances.clear();
  const calibration::CalibrationReport report = calibration::Calibrate(world.observations, {});
  const nlohmann::json j = CalibrationReportJson(world.observations, report, {});
  EXPECT_EQ(j["verification"]["calibrated_model"]["num_ok"], 0);
  EXPECT_TRUE(j["verification"]["calibrated_model"]["rms_error_m"].is_null());
  EXPECT_TRUE(j["verification"]["calibrated_model"]["max_error_m"].is_null());
  // No distance figure anywhere is a number 0 (a length of exactly 0 m is never measured).
  std::vector<std::string> keys;
  CollectKeys(j, "", &keys);
  int distance_figures = 0;
  for (const std::string& k : keys) {
    if (k.find("verification") == std::string::npos && k.find("predicted_3d_error") == std::string::npos) continue;
    if (!EndsWith(k, "_m")) continue;
    ++distance_figures;
    const nlohmann::json& v = j.at(nlohmann::json::json_pointer(k));
    EXPECT_FALSE(v.is_number() && v.get<double>() == 0.0) << k;
  }
  EXPECT_GT(distance_figures, 6);
  // The held-out reprojection needs no known distance: it is there, with its test.
  ASSERT_TRUE(j["heldout_reprojection"].is_object());
  EXPECT_EQ(j["heldout_reprojection"], j["methods"]["bundle"]["heldout_reprojection"]);
  EXPECT_TRUE(j["heldout_reprojection"]["test_passed"].is_boolean());
  EXPECT_GT(j["heldout_reprojection"]["calibrated_model"]["overall"]["num_residuals"].get<int>(), 0);
  EXPECT_EQ(j["heldout_reprojection"]["calibrated_model"]["poses"].size(),
            world.observations.PosesWithRole(PoseRole::kVerification).size());
  std::ostringstream text;
  PrintCalibrationSummary(world.observations, report, text);
  EXPECT_NE(text.str().find("held-out reprojection on"), std::string::npos) << text.str();
  EXPECT_EQ(text.str().find("held-out distances"), std::string::npos) << text.str();
}

// A flat target recorded with flange poses: the planar start's views carry their plane normal and their
// motion from the reference camera (against the truth), and a rival exactly when the plane left a view
// unresolved.
TEST(CalibrationReport, PlanarViewsCarryTheirNormalMotionAndUnresolvedRival) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3, /*flat_sheet=*/true);
  ObservationSet obs = testing::AsFlangePoseSet(world);
  const calibration::CalibrationReport report = calibration::Calibrate(obs, {});
  const nlohmann::json j = CalibrationReportJson(obs, report, {});
  const nlohmann::json& plane = j.at("hand_eye").at("start").at("plane");
  ASSERT_TRUE(plane.at("ok").get<bool>()) << plane.dump(1);
  const std::vector<int> poses = obs.PosesWithRole(PoseRole::kIdentification);
  int reference = -1;
  for (size_t k = 0; k < poses.size(); ++k) {
    if (obs.poses[poses[k]].id == plane.at("reference_pose")) reference = poses[k];
  }
  ASSERT_GE(reference, 0);
  const auto vec = [](const nlohmann::json& a) { return Eigen::Vector3d(a[0], a[1], a[2]); };
  const Eigen::Vector3d consensus = vec(plane.at("normal_in_reference_cam"));
  const nlohmann::json& views = plane.at("views");
  ASSERT_EQ(views.size(), poses.size());
  for (size_t k = 0; k < views.size(); ++k) {
    const nlohmann::json& v = views[k];
    if (!v.at("ok").get<bool>()) continue;
    if (poses[k] == reference) {
      EXPECT_TRUE(v.at("normal_in_reference_cam").is_null());
      continue;
    }
    EXPECT_LT(std::acos(std::min(1.0, vec(v.at("normal_in_reference_cam")).dot(consensus))), DegToRad(5)) << k;
    const Eigen::Matrix3d truth =
        (world.truth.base_from_cam[poses[k]].Inverse() * world.truth.base_from_cam[reference]).rotation;
    const Eigen::Matrix3d reported = ExpSO3<double>(vec(v.at("cam_from_reference").at("rotvec_rad")));
    EXPECT_LT(LogSO3(truth.transpose() * reported).norm(), DegToRad(1)) << "view " << k;
    EXPECT_EQ(v.at("rival").is_null(), v.at("resolved").get<bool>() || !v.at("has_rival").get<bool>()) << k;
    if (!v.at("rival").is_null()) {
      EXPECT_EQ(v.at("rival").at("normal_in_reference_cam").size(), 3u);
      EXPECT_EQ(v.at("rival").at("translation_plane_distances").size(), 3u);
    }
  }
}

// A flange-pose set with 1 mm / 0.05 deg of flange pose noise, stated: the pose-noise solve is the model written,
// and report.json's top-level f_x, hand-eye transform, held-out figure and plot dots, and the text summary's f_x
// and headline, are that solve's, not the exact-pose bundle's (whose f_x differs).
TEST(CalibrationReport, AFlangePoseSetsOutputsAllComeFromThePoseNoiseSolve) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 7);
  ObservationSet obs = testing::AsFlangePoseSet(world);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (PoseObservation& pose : obs.poses) {
    const double v[6] = {1e-3 * gauss(rng), 1e-3 * gauss(rng), 1e-3 * gauss(rng),
                         8.7e-4 * gauss(rng), 8.7e-4 * gauss(rng), 8.7e-4 * gauss(rng)};
    *pose.base_from_flange = *pose.base_from_flange * RigidFromTranslationRotvec(v);
  }
  obs.flange_translation_sigma_m = 1e-3;
  obs.flange_rotation_sigma_rad = 8.7e-4;
  const calibration::CalibrationReport report = calibration::Calibrate(obs, {});
  ASSERT_TRUE(report.PoseNoiseIsTheResult() && report.model.has_value()) << report.message;
  ASSERT_TRUE(report.pose_noise_heldout.has_value() && report.pose_noise_heldout->ok);
  const bundle::PoseNoiseReport& n = *report.pose_noise;
  const nlohmann::json j = CalibrationReportJson(obs, report, {});
  const double fx = j.at("fx_px").get<double>();
  EXPECT_EQ(fx, report.model->camera.fx_px);
  EXPECT_EQ(fx, n.intrinsics[kFx]);
  EXPECT_EQ(j.at("hand_eye").at("pose_noise").at("fx_px").get<double>(), fx);
  EXPECT_TRUE(j.at("hand_eye").at("pose_noise").at("is_the_result").get<bool>());
  EXPECT_NE(j.at("methods").at("bundle").at("fx_px").get<double>(), fx);  // the exact-pose solve's, a record
  const nlohmann::json& xyz = j.at("hand_eye").at("flange_from_cam").at("xyz_m");
  for (int k = 0; k < 3; ++k) EXPECT_EQ(xyz.at(k).get<double>(), n.flange_from_cam.translation[k]) << k;
  EXPECT_EQ(j.at("heldout_reprojection").at("calibrated_model").at("overall").at("rms_px").get<double>(),
            report.pose_noise_heldout->overall.rms_px);
  EXPECT_EQ(j.at("heldout_reprojection").at("test_passed").get<bool>(), report.pose_noise_heldout->overall.test_passed);
  const nlohmann::json& dots = j.at("methods").at("bundle").at("plot_data").at("dots_in_base");
  ASSERT_EQ(dots.size(), n.dots.size());
  const int first = dots.at(0).at("dot").get<int>();
  EXPECT_EQ(dots.at(0).at("xyz_m").at(0).get<double>(), n.dots.at(first).x());
  std::ostringstream text;
  PrintCalibrationSummary(obs, report, text);
  std::ostringstream fx_text;
  fx_text << std::fixed << std::setprecision(3) << fx;
  EXPECT_NE(text.str().find("pose-noise solve's"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("f_x = " + fx_text.str()), std::string::npos) << text.str();
  std::ostringstream rms;
  rms << std::fixed << std::setprecision(3) << report.pose_noise_heldout->overall.rms_px;
  EXPECT_NE(VerdictHeadline(report).find("held-out " + rms.str() + " px"), std::string::npos) << VerdictHeadline(report);
}

// The paper's Table 2 comes from the literature table, as printed there.
TEST(Literature, Table2RowsAsPrinted) {
  ASSERT_EQ(MengZhuang2001Table2().size(), 4u);
  const PaperTable2Row* row = NearestTable2Row("optimal", 0.45);
  ASSERT_NE(row, nullptr);
  EXPECT_EQ(row->noise_px, 0.5);
  EXPECT_EQ(row->position_mm.mean, 0.3035);
  EXPECT_EQ(NearestTable2Row("initial", 0.0)->noise_px, 0.2);
  EXPECT_EQ(NearestTable2Row("spiral", 0.2), nullptr);
  std::ostringstream text;
  simulation::BoundPoint point;
  point.setup.sigma_px = 0.5;
  PrintBoundSweep({point}, text);
  EXPECT_NE(text.str().find("optimal at noise II: 2.40e-4 rad, 0.30 mm, 0.35 px"), std::string::npos) << text.str();
}

}  // namespace
}  // namespace selfcal::report
