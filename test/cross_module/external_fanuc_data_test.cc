// Identification from the Fanuc laser-tracker session, read through io (a higher layer than external).
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "external/tracker_identification.h"
#include "io/fanuc_tracker_csv.h"

namespace selfcal::external {
namespace {

// The Fanuc laser-tracker session (README in the folder). Not copied into the repository.
std::string FanucFolder() { return std::string(SELFCAL_SHARED_DATA_DIR) + "/fanuc-lasertracker-kinident"; }

TEST(TrackerIdentification, FanucTrackerData) {
  const std::string file = FanucFolder() + "/N1N2N3Jval.csv";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "Fanuc laser-tracker data not found at " << FanucFolder();
  const Result<std::vector<io::FanucTrackerRow>> rows = io::LoadFanucTrackerCsv(file);
  ASSERT_TRUE(rows.ok()) << rows.status().ToString();
  ASSERT_EQ(rows->size(), 36u);
  std::vector<SmrTriple> points;
  std::vector<Eigen::VectorXd> joints;
  for (const auto& row : *rows) {
    points.push_back(row.smr_in_tracker_m);
    joints.push_back(row.joints_rad);
  }
  const TrackerIdentificationReport r = RunTrackerIdentification(points, joints, {});
  ASSERT_EQ(r.outcome, Outcome::kSuccess) << r.message;
  // Rigid nest: README 0.030-0.038 mm standard deviation.
  EXPECT_LT(r.distances.max_stddev_m, 1e-4);
  // The J2 sweep is a pure rotation of angle |dJ2| only with q3 = J3 + J2 (coupling right).
  EXPECT_NEAR(r.axes[1].angle_ratio, 1.0, 0.01);
  for (const AxisFit& a : r.axes) {
    std::cout << "joint " << a.joint << ": radial RMS " << a.rms_radial_m * 1e3 << " mm, out-of-plane RMS "
              << a.rms_out_of_plane_m * 1e3 << " mm, angle ratio " << a.angle_ratio << "\n";
    EXPECT_LT(a.rms_radial_m, 5e-4);
  }
  std::cout << "held-out RMS before " << r.holdout_before.rms_m * 1e3 << " mm, after " << r.holdout_after.rms_m * 1e3
            << " mm; in-sample after " << r.insample_after.rms_m * 1e3 << " mm\n";
  // Tracker ~0.05 mm, Fanuc repeatability ~0.03 mm, joint-dependent errors the geometric model cannot
  // hold (gear and compliance): a few tenths of a mm; 1 mm is the bound.
  EXPECT_LT(r.holdout_after.rms_m, r.holdout_before.rms_m);
  EXPECT_LT(r.holdout_after.rms_m, 1e-3);
}

}  // namespace
}  // namespace selfcal::external
