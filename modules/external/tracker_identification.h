// Module external (ARCHITECTURE.md): this header only; tested on the Fanuc data read by io in
// test/cross_module. Uses identification, kinematics, geometry, base.
//
// Kinematic identification from poses of a body measured by an external instrument (laser tracker: three
// SMRs in a nest on the flange), through the same relative-pose identification as the camera pipeline
// (identification/identification.h): the nest plays the camera's part, `flange_from_cam` is flange_from_nest.
//
// Steps (RunTrackerIdentification):
//  1. tracker_from_nest per row from its three SMRs (FrameFromThreePoints); the SMR distances must be
//     constant (rigid nest), their spread is reported.
//  2. Controller joints J -> model joints q (Fanuc couples J3 to J2: q3 = J3 + c J2, c = 1 by default,
//     checked by the J2 sweep being a pure rotation of angle |dJ2|).
//  3. Circle-point / screw-axis nominal model: rows that differ from the most common configuration q_ref in
//     one joint only form that joint's sweep; each SMR of a sweep moves on a circle whose plane normal is the
//     joint axis and whose centre lies on it (FitJointAxis, direction signed by the measured rotation sense).
//     The six axis lines at q_ref become a modified-DH + Hayati-beta table with the tracker as base frame
//     (ModelFromAxisLines); flange_from_nest follows from the reference row.
//  4. Identification over the free set of AnalyzeIdentifiability (metric: scale known) from
//     nest_ref_from_nest_i of the identification rows; interior rows of the sweeps are held out.
//  5. Held-out and in-sample position errors of the predicted nest_ref_from_nest_i, before (axis-fit model)
//     and after identification.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"
#include "identification/identifiability.h"
#include "identification/identification.h"
#include "kinematics/robot_model.h"

namespace selfcal::external {

// tracker_from_nest: origin at p1, x towards p2, z along (p2 - p1) x (p3 - p1), y = z x x.
// Throws InvalidArgument when the points are (nearly) collinear or coincident.
Rigid3 FrameFromThreePoints(const Eigen::Vector3d& p1, const Eigen::Vector3d& p2, const Eigen::Vector3d& p3);

using SmrTriple = std::array<Eigen::Vector3d, 3>;

// Distances |p1p2|, |p2p3|, |p1p3| over the rows: mean, standard deviation, max - min (m).
struct NestDistanceStats {
  std::array<double, 3> mean_m{}, stddev_m{}, range_m{};
  double max_stddev_m = 0, max_range_m = 0;
};
NestDistanceStats NestDistances(const std::vector<SmrTriple>& rows);

// Plane + circle through points (>= 3): least-squares plane (SVD), then the algebraic (Kasa) circle in it,
// exact for noise-free points.
struct CircleFit {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, sign arbitrary
  double radius_m = 0;
  double rms_radial_m = 0;        // RMS of |p - centre|_in_plane - radius
  double rms_out_of_plane_m = 0;  // RMS distance to the plane
};
CircleFit FitCircle(const std::vector<Eigen::Vector3d>& points);

// One joint's axis line in the tracker frame from its sweep.
struct AxisFit {
  int joint = 0;                       // 1-based
  std::vector<int> rows;               // indices into the input rows
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit; rotation sense of increasing q
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       // mean of the three circle centres
  double rms_radial_m = 0, rms_out_of_plane_m = 0;       // over the three SMR circles
  double max_centre_off_axis_m = 0;    // distance of each SMR circle centre from the averaged line
  double angle_ratio = 0;              // measured rotation angle / |dq|, mean over row pairs (1 = coupling right)
  double normal_vs_rotation_rad = 0;   // angle between plane normal and measured rotation axis
};

// `poses` tracker_from_nest and `q` the model joint of the swept joint, per sweep row (>= 3 distinct
// positions). Returns false (with *why) when the sweep is degenerate.
bool FitJointAxis(const std::vector<SmrTriple>& points, const std::vector<Rigid3>& poses, const std::vector<double>& q,
                  AxisFit* fit, std::string* why);

// Modified-DH + Hayati table from six (or n) axis lines expressed at joint configuration q_ref, base frame =
// the frame of the lines. Consecutive axes within parallel_tol_rad of parallel get a Hayati beta (d of the
// first of the pair kept at the previous foot point); the others the common normal. Frame n has its
// origin at the foot of the last common normal and link_n_from_flange = identity; flange_from_cam is
// identity (set it afterwards). The model predicts the lines exactly: axis i of BaseFromFlange at q_ref.
RobotModel ModelFromAxisLines(const std::string& name, const std::vector<Eigen::Vector3d>& directions,
                              const std::vector<Eigen::Vector3d>& points, const Eigen::VectorXd& q_ref,
                              double parallel_tol_rad = 0.05);

// Controller joints (rad) -> model joints: q = J, q3 += j3_coupling * J2.
Eigen::VectorXd ModelJointsFromController(const Eigen::VectorXd& controller_rad, double j3_coupling);

struct ErrorStats {
  int count = 0;
  double mean_m = 0, rms_m = 0, max_m = 0;
  double rms_rotation_rad = 0;
};

// The most a row's SMR distance may differ from the median over all rows: the nest is rigid (the Fanuc data
// spread 0.17 mm); more is a wrong value (the mutation campaign's 1e-300 for -804.9 mm gave an arm of
// 10 m links), refused naming the row.
inline constexpr double kMaxNestDistanceChangeM = 5e-3;

struct TrackerIdentificationOptions {
  // Rows i (0-based) with i % N == 1 are held out (0: none). With N = 3 on 6-row sweeps these are the 2nd
  // and 5th row of each sweep: interior, so every joint keeps its full range in the identification set.
  int holdout_every = 3;
  double j3_coupling = 1.0;       // q3 = J3 + c J2 (Fanuc)
  double parallel_tol_rad = 0.05;
  identification::IdentificationOptions identification = [] {
    identification::IdentificationOptions o;
    o.sigma_position_m = 5e-5;     // tracker ~0.05 mm
    o.sigma_rotation_rad = 2e-4;   // 0.05 mm over ~250 mm SMR spacing
    return o;
  }();
  std::string Validate() const;
};

enum class Outcome { kNotRun, kSuccess, kInvalidInput, kDegenerate, kNoConvergence, kFailure };
const char* OutcomeName(Outcome outcome);

struct TrackerIdentificationReport {
  Outcome outcome = Outcome::kNotRun;
  std::string message;
  int problem_row = -1;  // the input row (0-based) a refusal names ("row N" in `message`), else -1
  NestDistanceStats distances;
  Eigen::VectorXd q_ref;                 // model joints of the most common configuration
  // Rows at q_ref modulo 2 pi (the same pose reached again, e.g. J4 = +-360 deg) and the largest distance
  // between their measured nest origins: the repeatability floor of the data.
  int repeat_rows = 0;
  double repeat_max_m = 0;
  std::vector<AxisFit> axes;             // one per joint, from identification rows only
  RobotModel nominal;                    // from the axis lines, flange_from_cam = flange_from_nest
  Eigen::VectorXd rho_nominal, rho_identified;
  int reference_row = -1;
  std::vector<int> identification_rows, holdout_rows;
  identification::IdentifiabilityReport identifiability;
  identification::IdentificationReport identification;
  // |t_pred - t_meas| of nest_ref_from_nest_i (rows != reference), axis-fit model (before) and identified.
  ErrorStats holdout_before, holdout_after, insample_before, insample_after;
};

// `points` the three SMRs per row (tracker frame, m), `controller_joints` J per row (rad).
TrackerIdentificationReport RunTrackerIdentification(const std::vector<SmrTriple>& points,
                                                     const std::vector<Eigen::VectorXd>& controller_joints,
                                                     const TrackerIdentificationOptions& options);

// Errors of a model's predicted nest_ref_from_nest_i against the measured ones over `rows`.
ErrorStats RelativePoseErrors(const RobotModel& model, const Eigen::VectorXd& rho, const std::vector<Eigen::VectorXd>& q,
                              const std::vector<Rigid3>& tracker_from_nest, int reference_row,
                              const std::vector<int>& rows);

}  // namespace selfcal::external
