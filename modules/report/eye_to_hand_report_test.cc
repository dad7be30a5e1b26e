// The configuration in the reports (issue 40): report.json's `configuration`, the calibrated fixed camera under
// `hand_eye.base_from_cam` of an eye-to-hand flange-pose set, the text summary's and report.html's configuration.
// The report is built by hand (no solve): what is checked is where the writers put the model's values.
#include <sstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "report/calibration_report.h"
#include "report/html_report.h"

namespace selfcal::report {
namespace {

ObservationSet FlangeSet(CameraMount mount) {
  ObservationSet set;
  set.robot = FlangePoseModel(Rigid3());
  set.robot.mount = mount;
  return set;
}

// An accepted flange-pose calibration whose model holds distinct eye-in-hand and eye-to-hand transforms.
calibration::CalibrationReport ReportOf(CameraMount mount) {
  calibration::CalibrationReport report;
  report.verdict = calibration::Verdict::kAccepted;
  report.hand_eye_start = calibration::HandEyeStartReport{};
  report.bundle = calibration::BundleStageReport{};
  calibration::CalibratedModel model;
  model.robot = FlangePoseModel(Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.01, 0.02, 0.03)));
  model.robot.mount = mount;
  model.robot.base_from_cam = Rigid3(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                                     Eigen::Vector3d(0.954, -0.0512, 0.4762));
  // Each transform's own: a writer that took the other's would show the wrong sigma.
  (mount == CameraMount::kEyeToHand ? model.base_from_cam_stddev : model.flange_from_cam_stddev) << 1e-3, 2e-3, 3e-3,
      1e-3, 1e-3, 1e-3;
  report.model = model;
  return report;
}

TEST(EyeToHandReport, TheJsonGivesTheConfigurationAndTheFixedCamera) {
  const nlohmann::json e2h = CalibrationReportJson(FlangeSet(CameraMount::kEyeToHand), ReportOf(CameraMount::kEyeToHand), {});
  EXPECT_EQ(e2h["configuration"], "eye_to_hand");
  ASSERT_TRUE(e2h["hand_eye"].contains("base_from_cam")) << e2h["hand_eye"].dump();
  EXPECT_FALSE(e2h["hand_eye"].contains("flange_from_cam"));
  const nlohmann::json& x = e2h["hand_eye"]["base_from_cam"];
  EXPECT_EQ(x["xyz_m"][0].get<double>(), 0.954);
  EXPECT_NEAR(x["rotvec_rad"][2].get<double>(), 0.5, 1e-15);
  EXPECT_EQ(x["stddev"]["xyz_m"][2].get<double>(), 3e-3);
  EXPECT_NE(x["stddev"]["frame"].get<std::string>().find("base_from_cam"), std::string::npos);

  const nlohmann::json e2h_refused = CalibrationReportJson(FlangeSet(CameraMount::kEyeToHand), [] {
    calibration::CalibrationReport r = ReportOf(CameraMount::kEyeToHand);
    r.model.reset();
    return r;
  }(), {});
  EXPECT_TRUE(e2h_refused["hand_eye"]["base_from_cam"].is_null());  // the key follows the set, not the model

  const nlohmann::json eih = CalibrationReportJson(FlangeSet(CameraMount::kEyeInHand), ReportOf(CameraMount::kEyeInHand), {});
  EXPECT_EQ(eih["configuration"], "eye_in_hand");
  EXPECT_EQ(eih["hand_eye"]["flange_from_cam"]["xyz_m"][2].get<double>(), 0.03);
  EXPECT_FALSE(eih["hand_eye"].contains("base_from_cam"));
}

TEST(EyeToHandReport, TheSummaryAndThePageSayWhichConfiguration) {
  std::ostringstream e2h, eih;
  PrintCalibrationSummary(FlangeSet(CameraMount::kEyeToHand), ReportOf(CameraMount::kEyeToHand), e2h);
  EXPECT_EQ(e2h.str().rfind("configuration: eye_to_hand (the camera fixed in the robot base frame", 0), 0u) << e2h.str();
  EXPECT_NE(e2h.str().find("base_from_cam: translation [954.000, -51.200, 476.200] mm"), std::string::npos) << e2h.str();
  EXPECT_EQ(e2h.str().find("flange_from_cam"), std::string::npos) << e2h.str();
  PrintCalibrationSummary(FlangeSet(CameraMount::kEyeInHand), ReportOf(CameraMount::kEyeInHand), eih);
  EXPECT_EQ(eih.str().rfind("configuration: eye_in_hand (the camera on the flange", 0), 0u) << eih.str();
  EXPECT_NE(eih.str().find("flange_from_cam: translation [10.000, 20.000, 30.000] mm"), std::string::npos) << eih.str();

  const std::string html = CalibrationReportHtml(
      CalibrationReportJson(FlangeSet(CameraMount::kEyeToHand), ReportOf(CameraMount::kEyeToHand), {}), "");
  EXPECT_NE(html.find("<td>eye_to_hand</td>"), std::string::npos);
  EXPECT_NE(html.find("base_from_cam translation (mm)"), std::string::npos);
}

}  // namespace
}  // namespace selfcal::report
