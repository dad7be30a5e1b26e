// The bundle's Levenberg-Marquardt with the dots eliminated (kinematic_lm.h) against the solve it
// replaced, Ceres' trust-region LM with DENSE_SCHUR (ceres_reference_solve.h), on the same problems: the
// same iterations, tests and termination, the same point to round-off.
#include "bundle/kinematic_lm.h"

#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "bundle/bundle_test_util.h"
#include "bundle/ceres_reference_solve.h"

namespace selfcal::bundle {
namespace {

using internal::LmOptions;
using internal::LmSummary;

struct Case {
  const char* label;
  double noise_px;
  int outliers;           // observations moved to random pixels (the Huber loss at work)
  bool robust;
  IntrinsicsMask intrinsics;
};

// The problem of a simulated PUMA world from the nominal kinematics and the true dots moved by 2 mm, its
// free set the computed gauge.
struct Problem {
  internal::BundleData data;
  internal::BundleState start;
  std::vector<int> free, free_intrinsics;
};

Problem MakeProblem(const Case& c, uint64_t seed) {
  ObservationSet obs = testing::World(c.noise_px, seed, seed).observations;
  std::mt19937_64 rng(seed);
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  std::uniform_int_distribution<int> pick_pose(0, static_cast<int>(id_poses.size()) - 1), pick_dot(0, 79);
  std::uniform_real_distribution<double> u(0, obs.camera.width_px - 1), v(0, obs.camera.height_px - 1);
  for (int k = 0; k < c.outliers; ++k) {
    PoseObservation& pose = obs.poses[id_poses[pick_pose(rng)]];
    auto it = pose.dots_px.find(pick_dot(rng));
    if (it != pose.dots_px.end()) it->second = Eigen::Vector2d(u(rng), v(rng));
  }
  Problem p;
  p.data = internal::MakeBundleData(obs, 1e-6);
  p.start.rho = KinematicParameters::Nominal(obs.robot);
  p.start.intrinsics = IntrinsicsOf(obs.camera);
  const sim::SimResult truth = testing::World(c.noise_px, seed, seed);
  std::normal_distribution<double> move(0.0, 0.002);
  for (int id : p.data.dot_ids) {
    p.start.dots.push_back(truth.truth.dots_in_base[id] + Eigen::Vector3d(move(rng), move(rng), move(rng)));
  }
  internal::Gauge gauge;
  EXPECT_TRUE(internal::AnalyzeGauge(p.data, p.start, c.intrinsics, 1e-9, &gauge));
  p.free = gauge.free_kinematic;
  p.free_intrinsics = EstimatedIntrinsics(c.intrinsics);
  return p;
}

TEST(KinematicLm, TakesCeresDenseSchurStepsToTheSamePoint) {
  IntrinsicsMask fx_k1 = kFocalLengthOnly;
  fx_k1[kK1] = true;
  const Case cases[] = {{"0.2 px", 0.2, 0, false, kFocalLengthOnly},
                        {"0.5 px, f_x and k1", 0.5, 0, false, fx_k1},
                        {"0.2 px, 20 outliers, Huber", 0.2, 20, true, kFocalLengthOnly},
                        {"noise-free", 0.0, 0, false, kFocalLengthOnly}};
  for (const Case& c : cases) {
    for (uint64_t seed : {1, 2}) {
      const Problem p = MakeProblem(c, seed);
      LmOptions options;
      options.huber_threshold = c.robust ? 2.0 / p.data.sigma_px : 0.0;
      internal::BundleState ours = p.start, reference = p.start;
      const LmSummary a = internal::SolveKinematicBundle(p.data, p.free, p.free_intrinsics, options, &ours);
      const LmSummary b = internal::SolveWithCeres(p.data, p.free, p.free_intrinsics, options, &reference);
      const std::string label = std::string(c.label) + ", seed " + std::to_string(seed);
      EXPECT_EQ(a.termination, b.termination) << label << ": " << a.message << " / " << b.message;
      EXPECT_EQ(a.iterations, b.iterations) << label;
      EXPECT_NEAR(a.initial_cost, b.initial_cost, 1e-12 * b.initial_cost) << label;
      // Round-off apart, the same point: a relative 1e-9 of the cost (noise-free: its round-off floor, ~1e-18).
      EXPECT_NEAR(a.final_cost, b.final_cost, 1e-9 * b.final_cost + 1e-16) << label;
      double rho = 0, dot = 0, intrinsic = 0;
      for (int i : p.free) rho = std::max(rho, std::abs(ours.rho[i] - reference.rho[i]));
      for (int i : p.free_intrinsics) {
        intrinsic = std::max(intrinsic, std::abs(ours.intrinsics[i] - reference.intrinsics[i]) /
                                            std::max(1.0, std::abs(reference.intrinsics[i])));
      }
      for (size_t d = 0; d < ours.dots.size(); ++d) dot = std::max(dot, (ours.dots[d] - reference.dots[d]).norm());
      // A parameter's standard deviation here is 1e-5 m or rad or more: these are below a millionth of it
      // (measured: 3e-14 at most).
      EXPECT_LT(rho, 1e-11) << label;
      EXPECT_LT(dot, 1e-11) << label;
      EXPECT_LT(intrinsic, 1e-11) << label;
      std::cout << "[ figure ] " << label << ": " << a.iterations << " iterations (" << TerminationName(a.termination)
                << "), cost " << a.final_cost << " vs " << b.final_cost << "; largest difference rho " << rho
                << ", dots " << dot << " m, intrinsics " << intrinsic << " (relative)\n";
    }
  }
}

}  // namespace
}  // namespace selfcal::bundle
