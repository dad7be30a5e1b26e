#include "external/tracker_identification.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "base/status.h"

namespace selfcal::external {
namespace {

// An M-20iA-class 6R arm (modified DH, m), with J3 reported relative to J2 as on a Fanuc controller.
RobotModel FanucLikeArm() {
  const std::vector<DhRow> rows = {
      {0.0, 0.0, 0.525, 0.0},           {0.150, -kPi / 2, 0.0, -kPi / 2}, {0.790, 0.0, 0.0, 0.0},
      {0.150, -kPi / 2, 0.860, 0.0},    {0.0, kPi / 2, 0.0, 0.0},         {0.0, -kPi / 2, 0.100, 0.0}};
  const Rigid3 tracker_from_base(ExpSO3<double>(Eigen::Vector3d(0.01, -0.02, 0.39)), Eigen::Vector3d(1.4, 3.6, 0.67));
  const Rigid3 flange_from_nest(ExpSO3<double>(Eigen::Vector3d(0.7, -0.4, 2.1)), Eigen::Vector3d(0.19, -0.05, 0.20));
  return RobotModel::FromDh("fanuc-like", DhConvention::kModified, rows, std::vector<JointLimits>(6, {-4 * kPi, 4 * kPi}),
                            tracker_from_base, flange_from_nest);
}

// Controller joints (deg) of the HEAD session's layout: one joint swept at a time from (47, 0, 0, 0, 0, 0),
// the J2 sweep reporting J3 = -J2.
std::vector<Eigen::VectorXd> SweepJoints() {
  std::vector<Eigen::VectorXd> joints;
  auto add = [&joints](std::array<double, 6> deg) {
    Eigen::VectorXd j(6);
    for (int k = 0; k < 6; ++k) j[k] = DegToRad(deg[k]);
    joints.push_back(j);
  };
  for (double v : {-9., 3., 15., 27., 39., 51.}) add({v, 0, 0, 0, 0, 0});
  for (double v : {-30., -14., 2., 18., 34., 50.}) add({47, v, -v, 0, 0, 0});
  for (double v : {-55., -40., -25., -10., 5., 20.}) add({47, 0, v, 0, 0, 0});
  for (double v : {-360., -216., -72., 72., 216., 360.}) add({47, 0, 0, v, 0, 0});
  for (double v : {-75., -49., -23., 3., 29., 55.}) add({47, 0, 0, 0, v, 0});
  for (double v : {-360., -216., -72., 72., 216., 360.}) add({47, 0, 0, 0, 0, v});
  return joints;
}

const std::array<Eigen::Vector3d, 3> kSmrInNest = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.244, 0, 0),
                                                   Eigen::Vector3d(0.05, 0.24, 0.0)};

std::vector<SmrTriple> SimulateSmrs(const RobotModel& model, const std::vector<Eigen::VectorXd>& controller) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  std::vector<SmrTriple> points;
  for (const auto& j : controller) {
    const Rigid3 tracker_from_nest = BaseFromCam(model, rho, ModelJointsFromController(j, 1.0));
    points.push_back({tracker_from_nest * kSmrInNest[0], tracker_from_nest * kSmrInNest[1],
                      tracker_from_nest * kSmrInNest[2]});
  }
  return points;
}

TEST(FrameFromThreePoints, AxesAndOrigin) {
  const Rigid3 f = FrameFromThreePoints(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(3, 2, 3), Eigen::Vector3d(1, 5, 3));
  EXPECT_TRUE(f.translation.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(f.rotation.isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_THROW(FrameFromThreePoints(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 2 * Eigen::Vector3d::UnitX()),
               InvalidArgument);
}

TEST(FitCircle, ExactOnNoiseFreeArc) {
  const Eigen::Vector3d centre(0.3, -1, 2), n = Eigen::Vector3d(1, 2, 2).normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector3d> pts;
  for (double t : {0.1, 0.5, 0.7, 1.9}) pts.push_back(centre + 0.4 * (std::cos(t) * u + std::sin(t) * v));
  const CircleFit c = FitCircle(pts);
  EXPECT_LT((c.centre - centre).norm(), 1e-12);
  EXPECT_NEAR(std::abs(c.normal.dot(n)), 1.0, 1e-12);
  EXPECT_NEAR(c.radius_m, 0.4, 1e-12);
}

TEST(TrackerIdentification, SyntheticAxesAndPredictionsExact) {
  const RobotModel truth = FanucLikeArm();
  const Eigen::VectorXd rho_truth = KinematicParameters::Nominal(truth);
  const std::vector<Eigen::VectorXd> controller = SweepJoints();
  const TrackerIdentificationReport r = RunTrackerIdentification(SimulateSmrs(truth, controller), controller, {});
  ASSERT_EQ(r.outcome, Outcome::kSuccess) << r.message;
  EXPECT_LT(r.distances.max_range_m, 1e-12);

  // Axis lines at q_ref = (47 deg, 0, ...): z axis and origin of each link frame of the truth.
  Rigid3 chain = truth.base_from_link0;
  for (int j = 0; j < 6; ++j) {
    const double* p = rho_truth.data() + KinematicParameters::JointOffset(j);
    chain = chain * LinkTransform<double>(p[0], p[1], p[2], r.q_ref[j] + p[3], p[4]);
    const AxisFit& fit = r.axes[j];
    EXPECT_LT((fit.direction - chain.rotation.col(2)).norm(), 1e-9) << "joint " << j + 1;
    const Eigen::Vector3d off = fit.point - chain.translation;
    EXPECT_LT((off - off.dot(fit.direction) * fit.direction).norm(), 1e-9) << "joint " << j + 1;
    EXPECT_NEAR(fit.angle_ratio, 1.0, 1e-9) << "joint " << j + 1;
    EXPECT_LT(fit.rms_radial_m + fit.rms_out_of_plane_m, 1e-9);
  }
  // The axis-fit model already predicts every row; identification keeps it there.
  for (size_t i = 0; i < controller.size(); ++i) {
    const Eigen::VectorXd q = ModelJointsFromController(controller[i], 1.0);
    const PoseDifference d =
        ComparePoses(BaseFromCam(truth, rho_truth, q), BaseFromCam(r.nominal, r.rho_nominal, q));
    EXPECT_LT(d.position_m, 1e-9) << "row " << i;
    EXPECT_LT(d.rotation_rad, 1e-9) << "row " << i;
  }
  EXPECT_LT(r.holdout_before.max_m, 1e-9);
  EXPECT_LT(r.holdout_after.max_m, 1e-9);
  EXPECT_LT(r.insample_after.max_m, 1e-9);
}

// A row whose reflectors are collinear (a file's value of 1e308) was an internal error; it is a degenerate
// input, named by its row.
TEST(TrackerIdentification, CollinearReflectorsAreRefusedByRow) {
  const std::vector<Eigen::VectorXd> controller = SweepJoints();
  std::vector<SmrTriple> points = SimulateSmrs(FanucLikeArm(), controller);
  points[4][2] = points[4][0] + 2.0 * (points[4][1] - points[4][0]);
  const TrackerIdentificationReport r = RunTrackerIdentification(points, controller, {});
  EXPECT_EQ(r.outcome, Outcome::kDegenerate);
  EXPECT_NE(r.message.find("row 5: the three SMRs are collinear"), std::string::npos) << r.message;
  EXPECT_EQ(r.problem_row, 4);
}

// The mutation campaign's 1e-300 for one coordinate (-804.9 mm) moved one SMR: an arm of 10 m links, refused
// when the model was written, naming no row. The rigid nest's distances name it.
TEST(TrackerIdentification, AMovedReflectorIsRefusedByRow) {
  const std::vector<Eigen::VectorXd> controller = SweepJoints();
  std::vector<SmrTriple> points = SimulateSmrs(FanucLikeArm(), controller);
  points[7][1].x() += 0.8;
  const TrackerIdentificationReport r = RunTrackerIdentification(points, controller, {});
  EXPECT_EQ(r.outcome, Outcome::kDegenerate);
  EXPECT_EQ(r.problem_row, 7);
  EXPECT_NE(r.message.find("row 8: an SMR distance differs from the median"), std::string::npos) << r.message;
}

// Axis lines 12 m apart (consistent rows: the nest is rigid) give a model that cannot be written; refused
// before identification, with the rows of the two sweeps, not when the model is written.
TEST(TrackerIdentification, AxisLinesFarApartAreRefusedWithTheirRows) {
  RobotModel far = FanucLikeArm();
  far.links[2].a = 12.0;
  const std::vector<Eigen::VectorXd> controller = SweepJoints();
  const TrackerIdentificationReport r = RunTrackerIdentification(SimulateSmrs(far, controller), controller, {});
  EXPECT_EQ(r.outcome, Outcome::kDegenerate);
  EXPECT_NE(r.message.find("joint 3: |a| or |d| above 10 m between the axis lines fitted to the rows (joint 2:"),
            std::string::npos) << r.message;
}

TEST(TrackerIdentification, SyntheticRecoversFromPerturbedStart) {
  const RobotModel truth = FanucLikeArm();
  const std::vector<Eigen::VectorXd> controller = SweepJoints();
  const std::vector<SmrTriple> points = SimulateSmrs(truth, controller);
  const TrackerIdentificationReport r = RunTrackerIdentification(points, controller, {});
  ASSERT_EQ(r.outcome, Outcome::kSuccess) << r.message;
  // Start 1 mm / 0.2 deg away on every free parameter; the identification must come back to predictions
  // equal to the measurements (noise-free), on held-out rows too.
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0, 1);
  const KinematicParameters params(6);
  Eigen::VectorXd start = r.rho_nominal;
  for (int i : r.identifiability.free_indices) {
    start[i] += g(rng) * (params.kind(i) == ParameterKind::kLength ? 1e-3 : DegToRad(0.2));
  }
  std::vector<Eigen::VectorXd> q, id_q;
  std::vector<Rigid3> tracker_from_nest;
  for (size_t i = 0; i < controller.size(); ++i) {
    q.push_back(ModelJointsFromController(controller[i], 1.0));
    tracker_from_nest.push_back(FrameFromThreePoints(points[i][0], points[i][1], points[i][2]));
  }
  std::vector<identification::RelativePoseMeasurement> meas;
  int id_ref = -1;
  for (int i : r.identification_rows) {
    if (i == r.reference_row) id_ref = static_cast<int>(id_q.size());
    else meas.push_back({static_cast<int>(id_q.size()), tracker_from_nest[r.reference_row].Inverse() * tracker_from_nest[i], true});
    id_q.push_back(q[i]);
  }
  const ErrorStats before = RelativePoseErrors(r.nominal, start, q, tracker_from_nest, r.reference_row, r.holdout_rows);
  EXPECT_GT(before.max_m, 1e-4);
  const identification::IdentificationReport id = identification::IdentifyFromRelativePoses(
      r.nominal, start, r.identifiability.free_indices, id_q, id_ref, meas, TrackerIdentificationOptions().identification);
  ASSERT_EQ(id.outcome, identification::Outcome::kConverged) << id.message;
  const ErrorStats after = RelativePoseErrors(r.nominal, id.rho, q, tracker_from_nest, r.reference_row, r.holdout_rows);
  EXPECT_LT(after.max_m, 1e-9);
  EXPECT_LT(after.rms_rotation_rad, 1e-9);
}

}  // namespace
}  // namespace selfcal::external
