#include "bundle/bundle_adjustment.h"

#include <cmath>
#include <iostream>
#include <random>
#include <set>

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "bundle/bundle_problem.h"
#include "bundle/bundle_test_util.h"
#include "identification/identifiability.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::bundle {
namespace {

using testing::Truth;
using testing::VerificationPoseErrors;
using testing::World;

constexpr double kExact = 1e-9;

// Every free parameter, f_x and every dot against the truth (same gauge: base and joint 1 at nominal).
void ExpectExact(const BundleReport& r, const sim::SimResult& world, const char* label) {
  ASSERT_EQ(r.outcome, Outcome::kConverged) << label << ": " << r.message;
  const KinematicParameters params(6);
  double max_param = 0, max_dot = 0;
  for (int i : r.free_indices) {
    EXPECT_NEAR(r.rho[i], world.truth.rho_true[i], kExact) << label << " " << params.name(i);
    max_param = std::max(max_param, std::abs(r.rho[i] - world.truth.rho_true[i]));
  }
  const double fx_true = world.truth.camera_true.fx_px;
  EXPECT_NEAR(r.fx_px, fx_true, kExact * fx_true) << label;
  ASSERT_EQ(r.dots_in_base.size(), world.truth.dots_in_base.size());
  for (const auto& [id, p] : r.dots_in_base) {
    EXPECT_LT((p - world.truth.dots_in_base[id]).norm(), kExact) << label << " dot " << id;
    max_dot = std::max(max_dot, (p - world.truth.dots_in_base[id]).norm());
  }
  std::cout << "[ figure ] " << label << ": max parameter error " << max_param << ", f_x error "
            << std::abs(r.fx_px - fx_true) << " px, max dot error " << max_dot << " m, " << r.iterations
            << " iterations, " << r.seconds * 1e3 << " ms\n";
}

// K1: the gauge is computed for this problem and named; it agrees with the relative-pose analysis with
// known scale (the yardstick), which is what the simulator perturbs.
TEST(BundleAdjustment, NoiseFreeFromNominalRecoversTheTruthWithTheComputedGauge) {
  const sim::SimResult world = World(0.0);
  const ObservationSet& obs = world.observations;
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
  ExpectExact(r, world, "noise 0, nominal start");
  EXPECT_EQ(r.free_indices.size(), 24u);
  EXPECT_EQ(r.generic_rank, 24);
  EXPECT_EQ(r.free_indices, world.truth.perturbed_indices);
  std::vector<Eigen::VectorXd> joints;
  for (int i : obs.PosesWithRole(PoseRole::kIdentification)) joints.push_back(obs.poses[i].joints_rad);
  const auto relative = identification::AnalyzeIdentifiability(obs.robot, KinematicParameters::Nominal(obs.robot),
                                                                joints, 0, {});
  EXPECT_EQ(r.free_indices, relative.free_indices);
  EXPECT_EQ(r.fixed_names, relative.fixed_names);
  for (const char* name : {"base.tx", "base.rz", "j1.alpha", "j1.a", "j1.beta", "j1.theta", "j1.d"}) {
    EXPECT_NE(std::find(r.fixed_names.begin(), r.fixed_names.end(), name), r.fixed_names.end()) << name;
  }
  EXPECT_EQ(r.null_combinations.size(), r.fixed_names.size());
  std::cout << "[ figure ] BA gauge: " << r.free_indices.size() << " free kinematic + f_x; fixed:";
  for (const std::string& n : r.fixed_names) std::cout << " " << n;
  std::cout << "\n";
  ASSERT_TRUE(r.covariance_available) << r.covariance_message;
  EXPECT_EQ(r.covariance_free.rows(), 25);
  for (int i = 0; i < r.stddev.size(); ++i) {
    const bool free = std::find(r.free_indices.begin(), r.free_indices.end(), i) != r.free_indices.end();
    EXPECT_EQ(std::isnan(r.stddev[i]), !free) << i;
  }
}

TEST(BundleAdjustment, NoiseFreeFromAPerturbedStartWithTheGaugeOfTheNominalModel) {
  const sim::SimResult world = World(0.0, 2, 2);
  const ObservationSet& obs = world.observations;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const KinematicParameters params(6);
  Eigen::VectorXd rho = world.truth.rho_true;
  for (int i : world.truth.perturbed_indices) {
    rho[i] += (params.kind(i) == ParameterKind::kLength ? 3e-3 : DegToRad(0.5)) * gauss(rng);
  }
  const BundleReport r = RunBundleAdjustment(obs, rho, 1.03 * world.truth.camera_true.fx_px, {});
  ExpectExact(r, world, "noise 0, perturbed start (3 mm, 0.5 deg, 3 % f_x)");
  // The gauge is analysed at the nominal model: at the perturbed start joints 2 and 3 are not exactly
  // parallel, and a rank taken there would free j3.d, which then runs off to tens of metres (K2).
  EXPECT_EQ(r.free_indices, world.truth.perturbed_indices);
}

TEST(BundleAdjustment, EstimatesK1WhenAsked) {
  const sim::SimResult world = World(0.0, 3, 3);
  BundleOptions options;
  options.intrinsics[kK1] = true;
  const ObservationSet& obs = world.observations;
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, options);
  ExpectExact(r, world, "noise 0, k1 estimated");
  EXPECT_NEAR(r.intrinsics[kK1], world.truth.camera_true.k1, kExact);
  EXPECT_EQ(r.covariance_free.rows(), 26);
}

TEST(BundleAdjustment, ExpressOnModelReproducesTheCameraPoses) {
  const RobotModel nominal = selfcal::testing::Puma560();
  Eigen::VectorXd rho = KinematicParameters::Nominal(nominal);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 1e-2);
  for (int i = 0; i < rho.size(); ++i) rho[i] += gauss(rng);
  RobotModel scaled = nominal;
  ScaleLengths(1.07, &scaled, &rho);
  const Eigen::VectorXd on_nominal = ExpressOnModel(nominal, scaled, rho);
  for (int k = 0; k < 5; ++k) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) q[j] = 10 * gauss(rng);
    EXPECT_TRUE(selfcal::testing::RigidNear(BaseFromCam(scaled, rho, q), BaseFromCam(nominal, on_nominal, q), 1e-12, 1e-12));
  }
}

// The analytic chain rule (pose cache + projection) against central differences, with every lens term
// non-zero and mu != 1: rho, all nine intrinsics, the dot.
TEST(BundleAdjustment, ReprojectionJacobianMatchesNumericDifferentiation) {
  const RobotModel robot = selfcal::testing::Puma560();
  const int n = robot.num_parameters();
  std::vector<int> columns(n);
  for (int i = 0; i < n; ++i) columns[i] = i;
  Eigen::VectorXd q(6);
  q << 0.1, 0.4, 2.6, 0.2, 0.7, -0.3;
  Eigen::VectorXd x(n + kNumIntrinsics + 3);  // rho, intrinsics, dot
  x.head(n) = KinematicParameters::Nominal(robot);
  const Rigid3 base_from_cam = BaseFromCam(robot, Eigen::VectorXd(x.head(n)), q);
  x.segment<kNumIntrinsics>(n) << 1000.0, 1.02, 322.5, 236.0, -0.08, 0.05, 0.002, -0.003, -0.01;
  x.tail(3) = base_from_cam * Eigen::Vector3d(0.1, -0.05, 0.6);
  const Eigen::Vector2d pixel(300, 250);
  internal::BundleData one;
  one.robot = robot;
  one.joints = {q};
  auto intrinsics_of = [&](const double* v) {
    IntrinsicsVector in;
    for (int k = 0; k < kNumIntrinsics; ++k) in[k] = v[n + k];
    return in;
  };
  auto f = [&](const double* v, double* out) {
    internal::PoseCache cache;
    internal::ComputePoseCache(one, 0, v, {}, false, &cache);
    const double* d = v + n + kNumIntrinsics;
    internal::EvaluateReprojection(intrinsics_of(v), 0.5, cache, Eigen::Vector3d(d[0], d[1], d[2]), pixel, out,
                                   nullptr, nullptr, nullptr);
  };
  const Eigen::MatrixXd numeric = NumericJacobian(f, x, 2, 1e-7);
  internal::PoseCache cache;
  internal::ComputePoseCache(one, 0, x.data(), columns, true, &cache);
  double residual[2], d_intrinsics[2 * kNumIntrinsics], d_dot[6];
  std::vector<double> d_columns(2 * n);
  ASSERT_TRUE(internal::EvaluateReprojection(intrinsics_of(x.data()), 0.5, cache, x.tail<3>(), pixel, residual,
                                             d_columns.data(), d_intrinsics, d_dot));
  // The residual is camera.h's projection, bit for bit.
  double u = 0, v = 0;
  ASSERT_TRUE(ProjectWithIntrinsics<double>(x.data() + n, cache.rotation * x.tail<3>() + cache.translation, &u, &v));
  EXPECT_EQ(residual[0], (u - pixel.x()) * (1.0 / 0.5));
  EXPECT_EQ(residual[1], (v - pixel.y()) * (1.0 / 0.5));
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < n; ++c) EXPECT_NEAR(d_columns[r * n + c], numeric(r, c), 1e-5 * (1 + std::abs(numeric(r, c)))) << c;
    for (int k = 0; k < kNumIntrinsics; ++k) {
      const double expected = numeric(r, n + k);
      EXPECT_NEAR(d_intrinsics[r * kNumIntrinsics + k], expected, 1e-5 * (1 + std::abs(expected))) << IntrinsicName(k);
    }
    for (int c = 0; c < 3; ++c) {
      const double expected = numeric(r, n + kNumIntrinsics + c);
      EXPECT_NEAR(d_dot[3 * r + c], expected, 1e-4 * (1 + std::abs(expected)));
    }
  }
}

// The pose cache's derivatives (spatial twists, the right Jacobian of SO(3) for the base and camera
// corrections) against forward-mode autodiff of the chain, at corrections far from zero (0.3 rad, 5 cm):
// joint angles and a flange-pose set.
TEST(BundleAdjustment, PoseCacheDerivativesAreTheChainsDerivativesAtAnyCorrection) {
  const RobotModel robot = selfcal::testing::Puma560();
  const int n = robot.num_parameters();
  std::vector<int> columns(n);
  for (int i = 0; i < n; ++i) columns[i] = i;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  for (int i = 0; i < n; ++i) rho[i] += (i % 6 < 3 ? 0.05 : 0.3) * u(rng);
  internal::BundleData joints, flange;
  joints.robot = flange.robot = robot;
  Eigen::VectorXd q(6);
  q << 0.1, 0.4, 2.6, 0.2, 0.7, -0.3;
  joints.joints = {q};
  flange.joints = {Eigen::VectorXd()};
  flange.base_from_flange = {BaseFromFlange(robot, KinematicParameters::Nominal(robot), q)};
  using Jet = ceres::Jet<double, 1>;
  for (const internal::BundleData* data : {&joints, &flange}) {
    internal::PoseCache cache;
    internal::ComputePoseCache(*data, 0, rho.data(), columns, true, &cache);
    double worst = 0;
    for (int k = 0; k < n; ++k) {
      std::vector<Jet> rho_jet(n), q_jet(q.size());
      for (int i = 0; i < n; ++i) rho_jet[i] = Jet(rho[i]);
      rho_jet[k].v[0] = 1.0;
      for (int j = 0; j < q.size(); ++j) q_jet[j] = Jet(q[j]);
      const Rigid3T<Jet> base_from_cam = data->base_from_flange.empty()
                                             ? BaseFromCam<Jet>(robot, rho_jet.data(), q_jet.data())
                                             : BaseFromCamGivenFlange<Jet>(robot, rho_jet.data(), data->base_from_flange[0]);
      const Rigid3T<Jet> cam_from_base = base_from_cam.Inverse();
      // The twist's derivatives of cam_from_base = (R, t): d R = -R [omega]x, d t = -R v.
      const Eigen::Matrix3d d_rotation = -cache.rotation * Skew<double>(cache.omega[k]);
      const Eigen::Vector3d d_translation = -cache.rotation * cache.v[k];
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          worst = std::max(worst, std::abs(d_rotation(r, c) - cam_from_base.rotation(r, c).v[0]));
        }
        worst = std::max(worst, std::abs(d_translation[r] - cam_from_base.translation[r].v[0]));
      }
    }
    EXPECT_LT(worst, 1e-12) << (data == &joints ? "joint angles" : "flange poses");
  }
}

// The reduced Jacobian's Gram matrix is the Schur complement of the dots in the dense normal matrix.
TEST(BundleAdjustment, ReducedJacobianIsTheSchurComplementOfTheDots) {
  const sim::SimResult world = World(0.0);
  ObservationSet obs = world.observations;
  obs.poses.resize(5);
  for (PoseObservation& p : obs.poses) {
    for (auto it = p.dots_px.begin(); it != p.dots_px.end();) it = it->first >= 8 ? p.dots_px.erase(it) : std::next(it);
  }
  const internal::BundleData data = internal::MakeBundleData(obs, 1e-3);
  ASSERT_EQ(data.yardsticks.size(), 1u);
  internal::BundleState state{world.truth.rho_true, IntrinsicsOf(world.truth.camera_true), {}};
  for (int id : data.dot_ids) state.dots.push_back(world.truth.dots_in_base[id]);
  internal::GlobalColumns columns;
  columns.kinematic = world.truth.perturbed_indices;
  columns.intrinsics = {kFx};
  const int ng = columns.size(), nx = 3 * static_cast<int>(data.dot_ids.size());
  Eigen::MatrixXd reduced;
  ASSERT_TRUE(internal::ReducedJacobian(data, state, columns, &reduced));
  // Dense Jacobian by central differences of the whitened residuals.
  auto residuals = [&](const Eigen::VectorXd& x) {
    internal::BundleState s = state;
    for (size_t k = 0; k < columns.kinematic.size(); ++k) s.rho[columns.kinematic[k]] = x[k];
    s.intrinsics[kFx] = x[ng - 1];
    for (size_t d = 0; d < s.dots.size(); ++d) s.dots[d] = x.segment<3>(ng + 3 * d);
    Eigen::VectorXd out(2 * data.observations.size() + 1);
    for (size_t k = 0; k < data.observations.size(); ++k) {
      const internal::Observation& o = data.observations[k];
      internal::PoseCache cache;
      internal::ComputePoseCache(data, o.pose, s.rho.data(), {}, false, &cache);
      internal::EvaluateReprojection(s.intrinsics, data.sigma_px, cache, s.dots[o.dot], o.pixel, out.data() + 2 * k,
                                     nullptr, nullptr, nullptr);
    }
    const auto& y = data.yardsticks[0];
    out[out.size() - 1] = ((s.dots[y.dot_a] - s.dots[y.dot_b]).norm() - y.length_m) / data.yardstick_sigma_m;
    return out;
  };
  Eigen::VectorXd x(ng + nx);
  for (size_t k = 0; k < columns.kinematic.size(); ++k) x[k] = state.rho[columns.kinematic[k]];
  x[ng - 1] = state.intrinsics[kFx];
  for (size_t d = 0; d < state.dots.size(); ++d) x.segment<3>(ng + 3 * d) = state.dots[d];
  Eigen::MatrixXd j(residuals(x).size(), x.size());
  for (int c = 0; c < x.size(); ++c) {
    const double h = 1e-6 * std::max(1.0, std::abs(x[c]));
    Eigen::VectorXd xp = x, xm = x;
    xp[c] += h;
    xm[c] -= h;
    j.col(c) = (residuals(xp) - residuals(xm)) / (2 * h);
  }
  const Eigen::MatrixXd jg = j.leftCols(ng), jx = j.rightCols(nx);
  const Eigen::MatrixXd schur =
      jg.transpose() * jg - jg.transpose() * jx * (jx.transpose() * jx).ldlt().solve(jx.transpose() * jg);
  const Eigen::MatrixXd gram = reduced.transpose() * reduced;
  EXPECT_LT((gram - schur).norm(), 1e-5 * schur.norm()) << (gram - schur).norm() << " vs " << schur.norm();
}

TEST(BundleAdjustment, CovarianceRefusesARankDeficientJacobianByName) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Random(10, 3);
  j.col(2) = 2 * j.col(0) - j.col(1);
  Eigen::MatrixXd covariance;
  std::string message;
  EXPECT_FALSE(internal::CovarianceFromJacobian(j, {"a", "b", "c"}, &covariance, &message));
  EXPECT_NE(message.find("rank deficient: a, b, c"), std::string::npos) << message;
}

// Outliers (K7): 2 % of the observations replaced by random pixels.
TEST(BundleAdjustment, OutliersAreRemovedByPoseAndDotAndTheResultHolds) {
  const sim::SimResult world = World(0.2, 4, 4);
  ObservationSet obs = world.observations;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, obs.camera.width_px - 1), v(0, obs.camera.height_px - 1);
  std::set<std::pair<std::string, int>> corrupted;
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  std::uniform_int_distribution<int> pick_pose(0, static_cast<int>(id_poses.size()) - 1), pick_dot(0, 79);
  while (corrupted.size() < 24) {  // 2 % of 15 x 80
    PoseObservation& pose = obs.poses[id_poses[pick_pose(rng)]];
    const int dot = pick_dot(rng);
    if (corrupted.insert({pose.id, dot}).second) pose.dots_px[dot] = Eigen::Vector2d(u(rng), v(rng));
  }
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
  ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
  std::set<std::pair<std::string, int>> removed;
  for (const RemovedObservation& o : r.removed) removed.insert({o.pose_id, o.dot_id});
  for (const auto& c : corrupted) EXPECT_TRUE(removed.count(c)) << "not removed: pose " << c.first << ", dot " << c.second;
  EXPECT_LE(removed.size(), corrupted.size() + 2);  // at most two inliers lost
  ASSERT_TRUE(r.covariance_available) << r.covariance_message;
  int worst = -1;
  double worst_z = 0;
  for (int i : r.free_indices) {
    const double z = std::abs(r.rho[i] - world.truth.rho_true[i]) / r.stddev[i];
    if (z > worst_z) worst_z = z, worst = i;
  }
  EXPECT_LT(worst_z, 3.0) << KinematicParameters(6).name(worst);
  EXPECT_LT(std::abs(r.fx_px - world.truth.camera_true.fx_px), 3 * r.fx_stddev);
  std::cout << "[ figure ] outliers: " << corrupted.size() << " corrupted, " << r.removed.size()
            << " removed; worst free parameter at " << worst_z << " sigma; " << r.seconds * 1e3 << " ms\n";
}

// Issue 16 (K1, K3): the gauge does not depend on the stated pixel noise. Before, 1e-10 px made the
// yardstick's rows vanish below the rank tolerance (j3.d fixed: a false "insufficient excitation") and
// 1e-150 px overflowed the weighted Jacobian (a crash in the QR of SelectColumns).
TEST(BundleAdjustment, GaugeIsTheSameAtEveryStatedPixelNoise) {
  const sim::SimResult world = World(0.0);
  const ObservationSet& obs = world.observations;
  internal::BundleState state{KinematicParameters::Nominal(obs.robot), IntrinsicsOf(obs.camera), {}};
  internal::BundleData data = internal::MakeBundleData(obs, 1e-6);
  for (int id : data.dot_ids) state.dots.push_back(world.truth.dots_in_base[id]);
  internal::Gauge reference;
  ASSERT_TRUE(internal::AnalyzeGauge(data, state, kFocalLengthOnly, BundleOptions().rank_tolerance, &reference));
  EXPECT_EQ(reference.free_kinematic, world.truth.perturbed_indices);
  for (double sigma_px : {1e-150, 1e-100, 1e-10, 1e-6, 0.02, 1.0, 100.0}) {
    data.sigma_px = sigma_px;
    internal::Gauge gauge;
    ASSERT_TRUE(internal::AnalyzeGauge(data, state, kFocalLengthOnly, BundleOptions().rank_tolerance, &gauge)) << sigma_px;
    EXPECT_EQ(gauge.free_kinematic, reference.free_kinematic) << sigma_px;
    EXPECT_EQ(gauge.fixed_names, reference.fixed_names) << sigma_px;
    EXPECT_TRUE(gauge.intrinsics_identifiable[kFx]) << sigma_px;
  }
}

TEST(BundleAdjustment, MissingYardstickLeavesTheScaleUnresolved) {
  sim::SimResult world = World(0.2);
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(world.observations.robot);
  ObservationSet obs = world.observations;
  obs.yardsticks.clear();
  EXPECT_EQ(RunBundleAdjustment(obs, rho0, obs.camera.fx_px, {}).outcome, Outcome::kScaleUnresolved);
  obs = world.observations;  // S1: one end seen in a single identification view
  for (int i = 1; i < 15; ++i) obs.poses[i].dots_px.erase(1);
  const BundleReport r = RunBundleAdjustment(obs, rho0, obs.camera.fx_px, {});
  EXPECT_EQ(r.outcome, Outcome::kScaleUnresolved) << r.message;
}

TEST(BundleAdjustment, NanPixelIsInvalidInputNamingPoseAndDot) {
  sim::SimResult world = World(0.2);
  world.observations.poses[3].dots_px[5] = Eigen::Vector2d(std::nan(""), 1.0);
  const BundleReport r = RunBundleAdjustment(world.observations, KinematicParameters::Nominal(world.observations.robot),
                                             world.observations.camera.fx_px, {});
  EXPECT_EQ(r.outcome, Outcome::kInvalidInput);
  EXPECT_NE(r.message.find("pose p03, dot 5"), std::string::npos) << r.message;
}

TEST(BundleAdjustment, BadOptionsAndStartAreInvalidInputListingEveryProblem) {
  const sim::SimResult world = World(0.2);
  const ObservationSet& obs = world.observations;
  BundleOptions options;
  options.huber_px = -1;
  options.rank_tolerance = 2;
  const BundleReport r = RunBundleAdjustment(obs, Eigen::VectorXd::Zero(5), std::nan(""), options);
  EXPECT_EQ(r.outcome, Outcome::kInvalidInput);
  for (const char* what : {"huber_px", "rank_tolerance", "rho_start has 5 entries", "fx_start"}) {
    EXPECT_NE(r.message.find(what), std::string::npos) << what << " in: " << r.message;
  }
}

TEST(BundleAdjustment, TooFewPosesAreDegenerate) {
  sim::SimResult world = World(0.2);
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(world.observations.robot);
  ObservationSet obs = world.observations;
  obs.poses.resize(2);
  EXPECT_EQ(RunBundleAdjustment(obs, rho0, obs.camera.fx_px, {}).outcome, Outcome::kDegenerate);
  obs = world.observations;
  obs.poses.resize(4);  // 3 motions, 18 constraints: fewer than the 24 generic parameters (K3)
  const BundleReport r = RunBundleAdjustment(obs, rho0, obs.camera.fx_px, {});
  EXPECT_EQ(r.outcome, Outcome::kDegenerate);
  EXPECT_NE(r.message.find("insufficient excitation"), std::string::npos) << r.message;
  std::cout << "[ figure ] 4 poses: " << r.message << "\n";
}

}  // namespace
}  // namespace selfcal::bundle
