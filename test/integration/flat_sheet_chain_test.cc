// The simulated flat dot sheet through the path a user's own images take (issue 13): the world rendered
// into a folder of PNG images with a joint-angle poses list (selfcal_render_sequence --detect-folder, a
// modified circle grid with a larger origin dot), `selfcal detect` naming the dots by that dot, and
// `selfcal calibrate` on the result, scored against the simulator's hidden truth at the bundle's own
// reported standard deviations.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/observations_file.h"
#include "sim/render_sequence.h"
#include "support/cli.h"

namespace selfcal {
namespace {

using testing::FreshDir;
using testing::RunBinary;
using testing::RunSelfcalInSource;

// The rendering: 8 x 8 dots of 4 mm radius 15 mm apart (origin dot 1.6 x larger), 2 grey levels of
// sensor noise, a 0.5 px defocus blur, 4 x 4 supersamples per pixel.
const std::string kRender = " --flat-sheet-grid 8x8 --spacing-mm 15 --noise 2 --blur 0.5 --supersampling 4 --detect-folder";
// The pixel noise stated to the calibration: what this renderer and detector give, measured against the
// truth below (RMS per axis of detected minus true projected centre over every dot of every image;
// the test checks it stays within the statement).
// The scale: the grid's diagonal from dot 0 to dot 63, 7 x 15 mm along each side.
const std::string kYardstick = " --yardstick 0,63,148.49242404917499 ";
constexpr double kStatedNoisePx = 0.015;

double Sqr(double x) { return x * x; }

// Wilson-Hilferty: the p-quantile of chi-square with k degrees of freedom, z the standard normal quantile.
double ChiSquareQuantile(double k, double z) { return k * std::pow(1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k)), 3); }

nlohmann::json ReadJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The value of a parameter row (report.json's bundle.parameters or hidden_truth.json's), in SI.
double SiValue(const nlohmann::json& row, const std::string& key) {
  return row.contains(key + "_m") ? row.at(key + "_m").get<double>() : row.at(key + "_rad").get<double>();
}

TEST(FlatSheetChain, RenderedGridDetectedAndCalibratedAtTheBundlesBound) {
  const auto dir = FreshDir("flat_sheet", "chain");
  const std::filesystem::path images = dir / "images";
  std::string output;
  ASSERT_EQ(RunBinary(SELFCAL_RENDER_SEQUENCE, images.string() + kRender, &output), 0) << output;
  const std::string obs_path = (dir / "observations.yaml").string();
  char noise[32];
  std::snprintf(noise, sizeof(noise), "%g", kStatedNoisePx);
  ASSERT_EQ(RunSelfcalInSource("detect --images " + images.string() + " --poses " + (images / "poses.yaml").string() +
                                   " --robot config/robots/puma560.yaml --camera-fx-px 1000 --grid 8x8 " + kYardstick +
                                   "--pixel-noise-px " + noise + " --out " + obs_path,
                               &output),
            0)
      << output;

  // Identities and the detector's pixel noise against the rendered truth: every dot of every image
  // named, each within 1 px of its own true centre (its neighbours are ~20 px away).
  Result<ObservationSet> obs = io::LoadObservations(obs_path);
  ASSERT_TRUE(obs.ok()) << obs.status().ToString();
  Result<sim::SequenceTruth> truth = sim::ReadSequenceTruth((images / sim::kSequenceTruthName).string());
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  ASSERT_EQ(obs->poses.size(), truth->frames.size());
  int verification = 0, named = 0, wrong = 0;
  double sum_sq = 0;
  for (size_t i = 0; i < obs->poses.size(); ++i) {
    const PoseObservation& pose = obs->poses[i];
    const sim::SequenceTruthFrame& frame = truth->frames[i];
    ASSERT_EQ(pose.id + ".png", frame.image);
    verification += pose.role == PoseRole::kVerification ? 1 : 0;
    EXPECT_EQ(pose.dots_px.size(), 64u) << pose.id;
    for (const auto& [id, uv] : pose.dots_px) {
      ASSERT_TRUE(id >= 0 && id < static_cast<int>(frame.dots.size())) << pose.id << " dot " << id;
      const Eigen::Vector2d error = uv - frame.dots[static_cast<size_t>(id)].projected_centre_px;
      ++named;
      if (error.norm() > 1.0) {
        ++wrong;
        continue;
      }
      sum_sq += error.squaredNorm();
    }
  }
  EXPECT_EQ(wrong, 0) << "dots named with another dot's id";
  EXPECT_EQ(verification, 10);
  const double detector_rms_px = std::sqrt(sum_sq / (2.0 * std::max(1, named - wrong)));
  std::printf("[ measured ] %d dots named, %d wrong; detector error %.4f px RMS per axis (stated %.3f px)\n", named,
              wrong, detector_rms_px, kStatedNoisePx);
  EXPECT_LE(detector_rms_px, kStatedNoisePx);
  EXPECT_GE(detector_rms_px, 0.5 * kStatedNoisePx) << "the stated noise is far above what the detector gives";

  const auto out = dir / "calibration";
  const int code = RunSelfcalInSource("calibrate " + obs_path + " --out " + out.string(), &output);
  const nlohmann::json report = ReadJson(out / "report.json");
  const nlohmann::json hidden = ReadJson(images / "hidden_truth.json");
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(report.at("verdict"), "accepted") << output;
  const nlohmann::json& bundle = report.at("methods").at("bundle");
  const nlohmann::json& heldout = bundle.at("heldout_reprojection");
  const nlohmann::json& overall = heldout.at("calibrated_model").at("overall_at_stated_noise");
  EXPECT_TRUE(heldout.at("test_passed").get<bool>()) << heldout.dump(1);
  std::printf("[ measured ] held-out reprojection %.4f px RMS at a stated noise of %.3f px (chi-square %.1f, limit %.1f)\n",
              overall.at("rms_px").get<double>(), kStatedNoisePx, overall.at("chi_square").get<double>(),
              overall.at("chi_square_limit").get<double>());

  // Every estimated quantity's error over its reported sigma: the free kinematic parameters (the hand-eye
  // transform's cam.* among them) and f_x.
  std::map<std::string, double> truth_of;
  for (const nlohmann::json& row : hidden.at("parameters")) truth_of[row.at("name")] = SiValue(row, "true");
  std::vector<std::pair<std::string, double>> z;
  for (const nlohmann::json& row : bundle.at("parameters")) {
    if (!row.at("free").get<bool>()) continue;
    const std::string name = row.at("name");
    const double sigma = SiValue(row, "stddev");
    z.emplace_back(name, (SiValue(row, "value") - truth_of.at(name)) / sigma);
  }
  z.emplace_back("fx", (bundle.at("fx_px").get<double>() - hidden.at("fx_px").get<double>()) /
                           bundle.at("fx_stddev_px").get<double>());
  double sum_z2 = 0;
  for (const auto& [name, value] : z) {
    EXPECT_LT(std::abs(value), 4.0) << name;
    sum_z2 += Sqr(value);
    if (name.rfind("cam.", 0) == 0 || name == "fx") std::printf("[ measured ] %s: error / sigma %+.2f\n", name.c_str(), value);
  }
  // Were the bundle's sigmas right and its errors independent Gaussians, sum z^2 would be chi-square
  // with k = the number of estimated quantities; the band holds the central 99.9 % of it (Wilson-Hilferty
  // quantiles at z = -+3.29). The marginal z's of a bundle are correlated, which keeps the mean of
  // z^2 at 1 but widens its spread, so this band is the narrowest honest one, not a loose one.
  const double k = static_cast<double>(z.size());
  const double rms_z = std::sqrt(sum_z2 / k);
  const double low = std::sqrt(ChiSquareQuantile(k, -3.29) / k), high = std::sqrt(ChiSquareQuantile(k, 3.29) / k);
  std::printf("[ measured ] %zu estimated quantities, RMS of error / sigma %.3f (band %.3f to %.3f)\n", z.size(), rms_z,
              low, high);
  EXPECT_GE(rms_z, low);
  EXPECT_LE(rms_z, high);
}

}  // namespace
}  // namespace selfcal
