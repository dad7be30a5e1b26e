// Planning in eye-to-hand: every view is the fixed camera seen from the flange (PointsFromCam), the scene
// the plate's dots in the flange frame.
#include <cmath>
#include <iostream>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "identification/identifiability.h"
#include "planning/eq39.h"
#include "planning/plan_check.h"
#include "planning/planner.h"
#include "planning/pose_twists.h"
#include "planning/view_geometry.h"
#include "sim/sim_world.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::planning {
namespace {

struct EyeToHandWorld {
  PlanningProblem problem;
  std::vector<Eigen::VectorXd> start;
};

// The PUMA 560 in the simulated eye-to-hand cell, the simulator's plate as the scene.
EyeToHandWorld MakeEyeToHandWorld() {
  EyeToHandWorld w;
  const testing::EyeToHandCell cell = testing::PumaEyeToHandCell();
  const RobotModel& robot = cell.robot;
  const sim::SimResult world = sim::Simulate(robot, cell.start, sim::SimOptions());
  EXPECT_TRUE(world.ok) << world.message;
  w.problem.robot = robot;
  w.problem.camera = world.observations.camera;
  w.problem.scene = Scene::FromDots(world.truth.dots_in_base);
  w.problem.constraints.image_margin_px = 2.0;
  w.problem.constraints.max_fx_stddev_rel = 0.01;  // as `plan --configuration eye_to_hand`: a small plate
  w.start = cell.start;
  return w;
}

TEST(EyeToHandPlanning, TwistsAreTheDerivativesOfPointsFromCam) {
  const EyeToHandWorld w = MakeEyeToHandWorld();
  const RobotModel& robot = w.problem.robot;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  const Eigen::VectorXd& q = w.start[7];
  const internal::CameraTwists<double> tw = internal::ComputeCameraTwists<double>(robot, q.data());
  const Rigid3 x = PointsFromCam(robot, rho, q);
  EXPECT_LT((tw.base_from_cam.translation - x.translation).norm(), 1e-12);
  EXPECT_LT((tw.base_from_cam.rotation - x.rotation).norm(), 1e-12);
  const double h = 1e-6;
  for (int k = 0; k < robot.num_parameters(); ++k) {
    Eigen::VectorXd plus = rho, minus = rho;
    plus[k] += h;
    minus[k] -= h;
    const Rigid3 a = PointsFromCam(robot, plus, q), b = PointsFromCam(robot, minus, q);
    const Eigen::Vector3d dp = (a.translation - b.translation) / (2 * h);
    const Eigen::Matrix3d dr = (a.rotation - b.rotation) / (2 * h);
    const Eigen::Vector3d w_k = tw.omega[k];
    Eigen::Matrix3d wx;
    wx << 0, -w_k.z(), w_k.y(), w_k.z(), 0, -w_k.x(), -w_k.y(), w_k.x(), 0;
    EXPECT_LT((dp - (w_k.cross(x.translation) + tw.v[k])).norm(), 1e-7) << "parameter " << k;
    EXPECT_LT((dr - wx * x.rotation).norm(), 1e-7) << "parameter " << k;
  }
  // The joint twists are the same values (theta_j moves the view as q_j does).
  Eigen::Matrix<double, 3, Eigen::Dynamic> omega, v;
  const Rigid3 y = internal::ComputeJointTwists<double>(robot, q.data(), &omega, &v);
  EXPECT_EQ(y.translation, tw.base_from_cam.translation);
  for (int j = 0; j < 6; ++j) {
    EXPECT_EQ(Eigen::Vector3d(omega.col(j)), tw.omega[KinematicParameters::JointOffset(j) + 3]) << j;
    EXPECT_EQ(Eigen::Vector3d(v.col(j)), tw.v[KinematicParameters::JointOffset(j) + 3]) << j;
  }
}

TEST(EyeToHandPlanning, DOptimalKeepsThePlateInViewFacingTheCameraAndRaisesTheInformation) {
  const EyeToHandWorld w = MakeEyeToHandWorld();
  PlannerOptions options;
  options.criterion = Criterion::kDOptimal;
  options.pool_size = 120;
  options.seed = 3;
  const PlanResult r = PlanMeasurements(w.problem, w.start, options);
  std::cout << "[ figures  ] eye-to-hand D-optimal: log det " << r.fisher_start.log_det << " -> "
            << r.fisher_final.log_det << ", pool " << r.pool_size << ", " << r.seconds << " s\n";
  ASSERT_TRUE(r.ok) << r.message << " (pool " << r.pool_size << ")";
  EXPECT_TRUE(r.check_final.ok) << r.check_final.Summary();
  EXPECT_GT(r.pool_size, 20);
  EXPECT_GT(r.fisher_final.log_det, r.fisher_start.log_det);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(w.problem.robot);
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const Rigid3 x = PointsFromCam(w.problem.robot, rho, r.poses[i]);
    EXPECT_LE(PlateViewingAngle(x, w.problem.scene.Centre()), w.problem.constraints.max_viewing_angle_rad) << i;
    for (const Eigen::Vector3d& p : w.problem.scene.dots_in_base) {
      const Eigen::Vector3d in_cam = x.Inverse() * p;
      ASSERT_GT(in_cam.z(), 0.25) << "pose " << i;
      const auto uv = Project(w.problem.camera, in_cam);
      ASSERT_TRUE(uv && InImage(w.problem.camera, *uv, 2.0)) << "pose " << i;
    }
  }
  const PlanResult again = PlanMeasurements(w.problem, w.start, options);
  for (size_t i = 0; i < r.poses.size(); ++i) EXPECT_EQ(again.poses[i], r.poses[i]) << i;
}

TEST(EyeToHandPlanning, CheckNamesAPlateSeenTooObliquely) {
  EyeToHandWorld w = MakeEyeToHandWorld();
  w.problem.num_identification_poses = 15;
  w.problem.constraints.max_viewing_angle_rad = DegToRad(5.0);
  const PlanCheck check = CheckPlan(w.problem, w.start, -1);
  bool named = false;
  for (const PlanProblemItem& p : check.problems) {
    if (p.issue != PlanIssue::kViewingAngle) continue;
    named = true;
    EXPECT_NE(p.message.find("more than 5.0 deg"), std::string::npos) << p.message;
  }
  EXPECT_TRUE(named) << check.Summary();
  w.problem.constraints.max_viewing_angle_rad = DegToRad(55.0);
  const PlanCheck fine = CheckPlan(w.problem, w.start, -1);
  for (const PlanProblemItem& p : fine.problems) EXPECT_NE(p.issue, PlanIssue::kViewingAngle) << p.message;
}

}  // namespace
}  // namespace selfcal::planning
