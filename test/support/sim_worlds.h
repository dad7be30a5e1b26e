// The standard simulated world of the pipeline and bundle tests, built in one place: the PUMA 560 of
// test_robots.h on the shipped initial arc (sim::MakeArcTrajectory defaults), default hidden errors.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/sim_world.h"

namespace selfcal::testing {

// Fails the calling test (non-fatally) if the trajectory or the simulation cannot be built.
sim::SimResult PumaArcWorld(double noise_px, uint64_t world_seed = 1, uint64_t noise_seed = 1,
                            bool flat_sheet = false);

// The same world with any SimOptions (e.g. the spacing rule of rendered sessions).
sim::SimResult PumaArcWorld(const sim::SimOptions& options);

// The PUMA 560 in the simulated eye-to-hand cell, as `plan`, `simulate` and `study --configuration
// eye_to_hand` build it from config/robots/puma560.yaml: the fixed camera sim::DefaultFixedCamera at its
// home_deg, and that cell's 25-pose start (sim::MakeEyeToHandTrajectory). Fails the calling test
// (non-fatally) if the start cannot be built.
struct EyeToHandCell {
  RobotModel robot;
  std::vector<Eigen::VectorXd> start;
};
EyeToHandCell PumaEyeToHandCell();

// The world's observations recorded as flange poses of the true arm (no robot, no joints, no nominal hand-eye
// transform): a flange-pose set whose truth is the world's.
ObservationSet AsFlangePoseSet(const sim::SimResult& world);

}  // namespace selfcal::testing
