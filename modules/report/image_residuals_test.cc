#include "report/image_residuals.h"

#include <cmath>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "report/calibration_report.h"
#include "support/sim_worlds.h"

namespace selfcal::report {
namespace {

using nlohmann::json;

// RFC 4180 lines: fields split at commas outside quotes, "" inside quotes one quote.
std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t k = 0; k < line.size(); ++k) {
      const char c = line[k];
      if (quoted && c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
        fields.back() += '"';
        ++k;
      } else if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += c;
      }
    }
    rows.push_back(fields);
  }
  return rows;
}

// Column name -> value, for every data row.
std::vector<std::map<std::string, std::string>> Rows(const std::string& csv) {
  const std::vector<std::vector<std::string>> lines = ParseCsv(csv);
  std::vector<std::map<std::string, std::string>> rows;
  for (size_t r = 1; r < lines.size(); ++r) {
    EXPECT_EQ(lines[r].size(), lines[0].size()) << "row " << r;
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < lines[0].size() && c < lines[r].size(); ++c) row[lines[0][c]] = lines[r][c];
    rows.push_back(row);
  }
  return rows;
}

// Per pose from report.json: the count, 2-D RMS and largest |r| of the residual rows, screened-out rows beside.
struct JsonFigures {
  int used = 0, screened = 0;
  double sum2 = 0, max = -1;
  int max_dot = -1;
};
std::map<std::string, JsonFigures> FromReportJson(const json& j) {
  std::map<std::string, JsonFigures> out;
  const json& plot = j.at("methods").at("bundle").at("plot_data");
  for (const char* key : {"identification_residuals", "heldout_residuals"}) {
    for (const json& r : plot.at(key)) {
      JsonFigures& f = out[r.at("pose").get<std::string>()];
      const double n = std::hypot(r.at("residual_px")[0].get<double>(), r.at("residual_px")[1].get<double>());
      ++f.used;
      f.sum2 += n * n;
      if (n > f.max) f.max = n, f.max_dot = r.at("dot");
    }
  }
  for (const json& r : j.at("methods").at("bundle").at("removed_observations")) {
    JsonFigures& f = out[r.at("pose").get<std::string>()];
    ++f.screened;
    if (r.at("residual_px").get<double>() > f.max) f.max = r.at("residual_px"), f.max_dot = r.at("dot");
  }
  return out;
}

// A joint-angle set with one detection moved 25 px: its image's row names that dot as its largest residual
// (about 25 px, screened out of the fit), every row's figures are report.json's, the other identification
// images' largest residuals are of the 0.2 px noise, and there are no camera pose errors (no free-camera
// poses). The outlier's pose id holds a comma and quotes: quoted in the file.
TEST(ImageResiduals, OneRowPerImageWithItsLargestResidualAsInReportJson) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 2, 2);
  ObservationSet& obs = world.observations;
  const int outlier_pose = obs.PosesWithRole(PoseRole::kIdentification)[3];
  obs.poses[outlier_pose].id = "p,\"3\"";  // quoted in the file
  const int outlier_dot = std::next(obs.poses[outlier_pose].dots_px.begin(), 5)->first;
  obs.poses[outlier_pose].dots_px[outlier_dot] += Eigen::Vector2d(25.0, 0.0);
  const calibration::CalibrationReport report = calibration::Calibrate(obs, {});
  ASSERT_TRUE(report.bundle.has_value()) << report.message;
  const std::string csv = ImageResidualsCsv(obs, report);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), kImageResidualsHeader);
  const std::vector<std::map<std::string, std::string>> rows = Rows(csv);
  ASSERT_EQ(rows.size(), obs.poses.size());
  const std::map<std::string, JsonFigures> expected = FromReportJson(CalibrationReportJson(obs, report, {}));
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::map<std::string, std::string>& row = rows[i];
    const PoseObservation& pose = obs.poses[i];
    SCOPED_TRACE(pose.id);
    EXPECT_EQ(row.at("pose"), pose.id);
    EXPECT_EQ(row.at("role"), PoseRoleName(pose.role));
    EXPECT_EQ(std::stoul(row.at("detections")), pose.dots_px.size());
    const JsonFigures& f = expected.at(pose.id);
    EXPECT_EQ(std::stoi(row.at("used")), f.used);
    EXPECT_EQ(std::stoi(row.at("screened_out")), f.screened);
    EXPECT_NEAR(std::stod(row.at("rms_px")), std::sqrt(f.sum2 / f.used), 1e-6);
    EXPECT_NEAR(std::stod(row.at("max_residual_px")), f.max, 1e-6);
    EXPECT_EQ(std::stoi(row.at("max_residual_dot")), f.max_dot);
    EXPECT_EQ(row.at("camera_translation_error_mm"), "");
    EXPECT_EQ(row.at("camera_rotation_error_deg"), "");
    if (static_cast<int>(i) == outlier_pose) {
      EXPECT_EQ(std::stoi(row.at("max_residual_dot")), outlier_dot);
      EXPECT_NEAR(std::stod(row.at("max_residual_px")), 25.0, 2.0);
      EXPECT_GE(std::stoi(row.at("screened_out")), 1);
    } else {
      // Identification: the fit's noise (measured up to 0.9 px); verification: a prediction along the arc
      // beyond the identification poses, its error growing with the distance (measured up to 2.0 px).
      EXPECT_LT(std::stod(row.at("max_residual_px")), pose.role == PoseRole::kIdentification ? 1.5 : 5.0);
    }
  }
}

// A flange-pose set: each image's camera pose from the images alone against the model's, in report.json
// (hand_eye.image_motions.camera_poses_from_images, apart from plot_data.camera_poses_from_model) and in
// the file's last two columns in mm and deg.
TEST(ImageResiduals, FlangePosesGiveEachImagesCameraPoseErrorAgainstTheModel) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = testing::AsFlangePoseSet(world);
  const calibration::CalibrationReport report = calibration::Calibrate(obs, {});
  ASSERT_TRUE(report.motion_check.has_value() && report.motion_check->ok) << report.message;
  const json j = CalibrationReportJson(obs, report, {});
  EXPECT_EQ(j.at("version"), 3);
  const json& plot = j.at("methods").at("bundle").at("plot_data");
  EXPECT_FALSE(plot.contains("camera_poses"));
  const json& model = plot.at("camera_poses_from_model");
  const json& images = j.at("hand_eye").at("image_motions").at("camera_poses_from_images");
  ASSERT_EQ(images.size(), obs.poses.size());
  ASSERT_EQ(model.size(), obs.poses.size());
  const std::vector<std::map<std::string, std::string>> rows = Rows(ImageResidualsCsv(obs, report));
  ASSERT_EQ(rows.size(), obs.poses.size());
  const Rigid3& flange_from_cam = report.model->robot.flange_from_cam;
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    SCOPED_TRACE(obs.poses[i].id);
    EXPECT_EQ(images[i].at("pose"), obs.poses[i].id);
    EXPECT_EQ(model[i].at("pose"), obs.poses[i].id);
    // The model's camera: the flange pose times the calibrated hand-eye transform.
    const Rigid3 expected_model = *obs.poses[i].base_from_flange * flange_from_cam;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(model[i].at("xyz_m")[k].get<double>(), expected_model.translation[k], 1e-9);
    // The image's own camera: its error against the model is the distance of the two reported poses.
    const Eigen::Vector3d t(images[i].at("xyz_m")[0], images[i].at("xyz_m")[1], images[i].at("xyz_m")[2]);
    const Eigen::Vector3d w(images[i].at("rotvec_rad")[0], images[i].at("rotvec_rad")[1], images[i].at("rotvec_rad")[2]);
    const double translation_m = (t - expected_model.translation).norm();
    const double rotation_rad = LogSO3(expected_model.rotation.transpose() * ExpSO3<double>(w)).norm();
    EXPECT_NEAR(images[i].at("model_translation_error_m").get<double>(), translation_m, 1e-9);
    EXPECT_NEAR(images[i].at("model_rotation_error_rad").get<double>(), rotation_rad, 1e-9);
    EXPECT_LT(translation_m, 1.5e-3);
    EXPECT_LT(rotation_rad, DegToRad(0.05));
    EXPECT_NEAR(std::stod(rows[i].at("camera_translation_error_mm")), translation_m * 1e3, 1e-6);
    EXPECT_NEAR(std::stod(rows[i].at("camera_rotation_error_deg")), rotation_rad * 180 / kPi, 1e-6);
  }
}

// The paper's method alone has no bundle: one row per image with its detections, every figure empty.
TEST(ImageResiduals, WithoutABundleEveryFigureIsEmpty) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 2, 2);
  calibration::CalibrateOptions options;
  options.method = calibration::Method::kPaper;
  const calibration::CalibrationReport report = calibration::Calibrate(world.observations, options);
  ASSERT_FALSE(report.bundle.has_value());
  const std::vector<std::map<std::string, std::string>> rows = Rows(ImageResidualsCsv(world.observations, report));
  ASSERT_EQ(rows.size(), world.observations.poses.size());
  for (const auto& row : rows) {
    EXPECT_FALSE(row.at("detections").empty());
    for (const char* column : {"used", "screened_out", "rms_px", "max_residual_px", "max_residual_dot",
                               "camera_translation_error_mm", "camera_rotation_error_deg"}) {
      EXPECT_EQ(row.at(column), "") << column;
    }
  }
}

}  // namespace
}  // namespace selfcal::report
