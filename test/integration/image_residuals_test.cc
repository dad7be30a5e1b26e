// image_residuals.csv, written by `selfcal calibrate` beside report.json (docs/report-format.md), read back
// as a script would: one row per image whose figures are report.json's, a detection moved by a known 25 px
// found as its image's largest residual, and on flange poses each image's own camera pose against the
// model's, a flange pose logged 3 deg off found as the image whose camera disagrees by 3 deg.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/observations_file.h"
#include "support/cli.h"
#include "support/sim_worlds.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::FreshDir;
using testing::RunSelfcal;

using Row = std::map<std::string, std::string>;

// The file's rows, by column name (no field here holds a comma or a quote).
std::vector<Row> ReadCsv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream split(line);
    std::string field;
    while (std::getline(split, field, ',')) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    if (header.empty()) {
      header = fields;
      continue;
    }
    EXPECT_EQ(fields.size(), header.size()) << line;
    Row row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

json ReadJson(const fs::path& path) { return json::parse(std::ifstream(path)); }

double Number(const Row& row, const std::string& column) { return std::stod(row.at(column)); }

// simulate (joint angles, 0.2 px), one detection of one identification image moved by 25 px, calibrate: the
// file has a row per pose in order, its rms and largest residual are report.json's residual rows', the moved
// detection is its image's largest residual (screened out of the fit), the other identification images'
// largest residuals are of the noise, and no camera pose error (a joint-angle set has no free-camera poses).
TEST(ImageResidualsCli, AMovedDetectionIsItsImagesLargestResidualAsInReportJson) {
  const fs::path dir = FreshDir("image_residuals", "outlier");
  std::string out;
  ASSERT_EQ(RunSelfcal("simulate --points --noise-px 0.2 --seed 5 --out " + (dir / "sim").string(), &out), 0) << out;
  Result<ObservationSet> loaded = io::LoadObservations((dir / "sim" / "observations.yaml").string());
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ObservationSet obs = *loaded;
  const int outlier_pose = obs.PosesWithRole(PoseRole::kIdentification)[3];
  const int outlier_dot = std::next(obs.poses[outlier_pose].dots_px.begin(), 5)->first;
  obs.poses[outlier_pose].dots_px[outlier_dot] += Eigen::Vector2d(0.0, 25.0);
  const fs::path file = dir / "sim" / "outlier.yaml";
  ASSERT_TRUE(io::SaveObservations(obs, file.string()).ok());
  RunSelfcal("calibrate " + file.string() + " --out " + (dir / "cal").string() + " --no-html", &out);
  ASSERT_TRUE(fs::exists(dir / "cal" / "image_residuals.csv")) << out;
  EXPECT_NE(out.find("per-image residuals: " + (dir / "cal" / "image_residuals.csv").string()), std::string::npos) << out;
  const std::vector<Row> rows = ReadCsv(dir / "cal" / "image_residuals.csv");
  const json report = ReadJson(dir / "cal" / "report.json");
  const json& plot = report.at("methods").at("bundle").at("plot_data");
  ASSERT_EQ(rows.size(), obs.poses.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& row = rows[i];
    SCOPED_TRACE(obs.poses[i].id);
    EXPECT_EQ(row.at("pose"), obs.poses[i].id);
    EXPECT_EQ(row.at("role"), PoseRoleName(obs.poses[i].role));
    EXPECT_EQ(std::stoul(row.at("detections")), obs.poses[i].dots_px.size());
    int used = 0;
    double sum2 = 0, largest = 0;
    const char* key = obs.poses[i].role == PoseRole::kIdentification ? "identification_residuals" : "heldout_residuals";
    for (const json& r : plot.at(key)) {
      if (r.at("pose") != obs.poses[i].id) continue;
      const double n = std::hypot(r.at("residual_px")[0].get<double>(), r.at("residual_px")[1].get<double>());
      ++used;
      sum2 += n * n;
      largest = std::max(largest, n);
    }
    int screened = 0;
    for (const json& r : report.at("methods").at("bundle").at("removed_observations")) {
      if (r.at("pose") != obs.poses[i].id) continue;
      ++screened;
      largest = std::max(largest, r.at("residual_px").get<double>());
    }
    // A verification image's detections left out by the held-out test as gross errors.
    for (const json& r : report.at("heldout_reprojection").at("calibrated_model").at("gross_errors")) {
      if (r.at("pose") != obs.poses[i].id) continue;
      ++screened;
      largest = std::max(largest, std::hypot(r.at("residual_px")[0].get<double>(), r.at("residual_px")[1].get<double>()));
    }
    EXPECT_EQ(std::stoi(row.at("used")), used);
    EXPECT_EQ(std::stoi(row.at("screened_out")), screened);
    EXPECT_NEAR(Number(row, "rms_px"), std::sqrt(sum2 / used), 2e-6);
    EXPECT_NEAR(Number(row, "max_residual_px"), largest, 2e-6);
    EXPECT_EQ(row.at("camera_translation_error_mm"), "");
    EXPECT_EQ(row.at("camera_rotation_error_deg"), "");
    if (static_cast<int>(i) == outlier_pose) {
      EXPECT_EQ(std::stoi(row.at("max_residual_dot")), outlier_dot);
      EXPECT_NEAR(Number(row, "max_residual_px"), 25.0, 2.0);
      EXPECT_GE(screened, 1);
    } else if (obs.poses[i].role == PoseRole::kIdentification) {
      EXPECT_LT(Number(row, "max_residual_px"), 1.5);
    }
  }
}

// Flange poses of the true arm (0.2 px), one logged 3 deg off: the file's camera pose errors are report.json's
// hand_eye.image_motions.camera_poses_from_images in mm and deg, the wrong pose's near 3 deg and the others'
// far below; the report (version 3) validates against docs/report.schema.json.
TEST(ImageResidualsCli, AFlangePoseLoggedOffIsTheImageWhoseCameraDisagreesWithTheModel) {
  const fs::path dir = FreshDir("image_residuals", "flange");
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = testing::AsFlangePoseSet(world);
  const size_t wrong = 4;
  obs.poses[wrong].base_from_flange->rotation =
      obs.poses[wrong].base_from_flange->rotation * ExpSO3<double>(Eigen::Vector3d(0, DegToRad(3.0), 0));
  ASSERT_TRUE(io::SaveObservations(obs, (dir / "flange.yaml").string()).ok());
  std::string out;
  RunSelfcal("calibrate " + (dir / "flange.yaml").string() + " --out " + (dir / "cal").string() + " --no-html", &out);
  ASSERT_TRUE(fs::exists(dir / "cal" / "image_residuals.csv")) << out;
  const std::vector<Row> rows = ReadCsv(dir / "cal" / "image_residuals.csv");
  const json report = ReadJson(dir / "cal" / "report.json");
  EXPECT_EQ(report.at("version"), 3);
  const json& images = report.at("hand_eye").at("image_motions").at("camera_poses_from_images");
  ASSERT_EQ(rows.size(), obs.poses.size());
  ASSERT_EQ(images.size(), obs.poses.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(obs.poses[i].id);
    EXPECT_EQ(images[i].at("pose"), rows[i].at("pose"));
    EXPECT_NEAR(Number(rows[i], "camera_translation_error_mm"),
                images[i].at("model_translation_error_m").get<double>() * 1e3, 2e-6);
    const double deg = Number(rows[i], "camera_rotation_error_deg");
    EXPECT_NEAR(deg, images[i].at("model_rotation_error_rad").get<double>() * 180 / kPi, 2e-6);
    if (i == wrong) {
      EXPECT_NEAR(deg, 3.0, 0.5);
    } else {
      EXPECT_LT(deg, 1.0);
    }
  }
  const std::string schema = std::string(SELFCAL_SOURCE_DIR) + "/docs/report.schema.json";
  const std::string validate = "/usr/bin/python3 -c \"import json, sys, jsonschema; "
                               "jsonschema.Draft202012Validator(json.load(open(sys.argv[1]))).validate(json.load(open(sys.argv[2])))\" " +
                               schema + " " + (dir / "cal" / "report.json").string();
  EXPECT_EQ(std::system(validate.c_str()), 0) << validate;
}

}  // namespace
}  // namespace selfcal
