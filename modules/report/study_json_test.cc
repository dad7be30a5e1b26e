#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "report/study_report.h"
#include "sim/trajectory_generator.h"
#include "simulation/study.h"
#include "support/test_robots.h"

namespace selfcal::report {
namespace {

// The study's wall times, which no two runs share, removed from its JSON document (every level).
void DropWallTimes(nlohmann::json* j) {
  if (j->is_object()) {
    for (const char* key : {"seconds_per_calibration", "seconds_per_solve", "seconds_total"}) j->erase(key);
  }
  if (j->is_object() || j->is_array()) {
    for (nlohmann::json& child : *j) DropWallTimes(&child);
  }
}

// `selfcal study`'s JSON is the same text on one thread and on three (its wall times apart): two runs at
// 0.2 px with the OpenCV comparison, the bounds, the bundle and a rendered row, so every section is
// filled.
TEST(StudyJson, SameDocumentOnOneAndOnThreeThreads) {
  const RobotModel puma = testing::Puma560();
  const sim::GeneratedTrajectory arc = sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions());
  ASSERT_TRUE(arc.ok) << arc.message;
  simulation::StudyOptions options;
  options.runs = 3;
  options.noise_levels_px = {0.2};
  options.sim.separation_dot_radius_m = options.rendered.dot_radius_m;
  options.rendered_levels = {{"img-I", 2, 0, 0.01}};
  std::string text[2];
  for (int k = 0; k < 2; ++k) {
    options.jobs = k == 0 ? 1 : 3;
    const simulation::StudyReport study = simulation::RunStudy(puma, {{"arc", arc.joints}}, options);
    nlohmann::json json = StudyJson(study, options);
    DropWallTimes(&json);
    text[k] = json.dump(1);
  }
  EXPECT_GT(text[0].size(), 1000u);
  EXPECT_NE(text[0].find("img-I"), std::string::npos);
  EXPECT_EQ(text[1], text[0]);
}

}  // namespace
}  // namespace selfcal::report
