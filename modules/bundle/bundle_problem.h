// Internal to the bundle module: the reprojection model with its analytic Jacobian, the reduced
// (dots-eliminated) Jacobian, and the rank selection. Shared by the solver, the covariance, the
// Cramer-Rao bound and the tests; Ceres stays out of this header.
//
// Global columns: entries of rho (a chosen subset), then the estimated intrinsics (camera/camera.h's
// Intrinsic order: fx, mu, cx, cy, k1, k2, p1, p2, k3). Rows are whitened: pixel residuals divided by
// sigma_px, yardstick residuals by yardstick_sigma_m.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "identification/rank_selection.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::bundle::internal {

struct Observation {
  int pose = -1;  // index into BundleData::joints
  int dot = -1;   // index into BundleData::dot_ids
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

struct Yardstick {
  int dot_a = -1, dot_b = -1;  // indices into BundleData::dot_ids
  double length_m = 0;
};

// The fixed inputs of one problem, poses and dots by index.
struct BundleData {
  RobotModel robot;
  CameraIntrinsics camera;  // the prior (image size, the start's triangulation); the solve's values: BundleState
  double sigma_px = 1;
  double yardstick_sigma_m = 1e-6;
  std::vector<std::string> pose_ids;
  std::vector<Eigen::VectorXd> joints;  // identification poses
  // A flange-pose set (ObservationSet::UsesFlangePoses): the recorded flange pose of each identification
  // pose, and joints holds empty vectors. Empty otherwise.
  std::vector<Rigid3> base_from_flange;
  std::vector<int> dot_ids;
  std::vector<Observation> observations;
  std::vector<Yardstick> yardsticks;
};

// A point of the problem.
struct BundleState {
  Eigen::VectorXd rho;
  IntrinsicsVector intrinsics{};      // every intrinsic, estimated or held
  std::vector<Eigen::Vector3d> dots;  // by dot index, the points' frame (base eye-in-hand, flange eye-to-hand)
};

struct GlobalColumns {
  std::vector<int> kinematic;   // rho indices
  std::vector<int> intrinsics;  // Intrinsic indices, ascending
  int size() const { return static_cast<int>(kinematic.size() + intrinsics.size()); }
};

// cam_from_points = (R, t) of one pose (PointsFromCam, or PointsFromCamGivenFlange for a flange-pose set:
// the points' frame is the base eye-in-hand, the flange eye-to-hand) and its derivative with respect to
// rho[columns[c]] as the spatial twist (omega[c], v[c]) of the camera in the points' frame: d R = -R [omega]x,
// d t = -R v.
struct PoseCache {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> omega, v;
};
Rigid3 PointsFromCamOfPose(const BundleData& data, int pose, const Eigen::VectorXd& rho);
void ComputePoseCache(const BundleData& data, int pose, const double* rho, const std::vector<int>& columns,
                      bool derivatives, PoseCache* out);

// Whitened residual (project(intrinsics, R p + t) - pixel) / sigma of one observation, the projection of
// camera/camera.h (ProjectWithIntrinsics, the same bits). Derivatives (each optional, row-major):
// d_columns 2 x cache.omega.size(), d_intrinsics 2 x kNumIntrinsics, d_dot 2 x 3. Returns false
// (outputs untouched) when the point is not in front of the camera or anything is non-finite.
bool EvaluateReprojection(const IntrinsicsVector& intrinsics, double sigma_px, const PoseCache& cache,
                          const Eigen::Vector3d& dot, const Eigen::Vector2d& pixel, double* residual, double* d_columns,
                          double* d_intrinsics, double* d_dot);

// Compressed reduced Jacobian: a matrix Rd with gc.size() columns and Rd^T Rd = J_g^T (I - P_dots) J_g,
// the Schur complement of the dots in the whitened normal matrix (J_g: global columns, P_dots: projection
// onto the dots' columns). Dots are eliminated group by group (dots joined by a yardstick form one
// group). Returns false when an observation cannot be evaluated at `state`.
//
// With `pose_errors` the matrix has 6 more columns per pose after the globals: the derivative of the
// whitened residuals with respect to a small motion (v, omega) of that pose's camera in its own frame
// (p_cam -> p_cam + omega x p_cam + v; m and rad), reduced the same way (error_model.h); pose_errors
// receives those columns' gradient J^T r and the whitened residuals' sum of squares at `state`.
struct PoseErrorColumns {
  Eigen::VectorXd gradient;  // 6 per pose: (v, omega)
  Eigen::VectorXd global_gradient;  // J^T r of the global columns
  Eigen::VectorXd global_norm_sq;   // their squared norms before the dots are eliminated
  double residual_sq = 0;
};
bool ReducedJacobian(const BundleData& data, const BundleState& state, const GlobalColumns& columns,
                     Eigen::MatrixXd* reduced, PoseErrorColumns* pose_errors = nullptr);

// Names of the global columns: rho names, then the intrinsics' ("fx", "cx", ...).
std::vector<std::string> GlobalNames(const GlobalColumns& columns, int num_joints);

// Greedy column order over all global columns (rho entries 0..n-1, then `num_intrinsics` intrinsic
// columns): the intrinsics in their order, then camera, base, alpha/a/theta/d joint by joint, betas last
// (as identification/identifiability.cc).
std::vector<int> SelectionOrder(int num_joints, int num_intrinsics);

// Inverse of jacobian^T jacobian through the SVD of the column-normalised matrix. Returns false, with a
// message naming the columns involved in the null space (K8), when it is rank deficient.
bool CovarianceFromJacobian(const Eigen::MatrixXd& jacobian, const std::vector<std::string>& names,
                            Eigen::MatrixXd* covariance, std::string* message);

// The identification poses of `observations`, every dot seen in at least two of them (dot ids
// ascending), their observations, and the yardsticks with both ends among those dots (none for a
// flange-pose set, whose scale the flange translations fix).
BundleData MakeBundleData(const ObservationSet& observations, double yardstick_sigma_m);

// The gauge and the free set of the problem at `state` (../shared/DESIGN.md section 4): SelectColumns on the
// reduced Jacobian of every rho entry plus the estimated intrinsics.
struct Gauge {
  std::vector<int> free_kinematic;  // rho indices, ascending
  std::vector<std::string> free_names, fixed_names, null_combinations;
  std::vector<std::string> held_names;  // held at their start by request (BundleOptions::held_parameters)
  IntrinsicsMask intrinsics_identifiable{};  // of the estimated ones, those the selection kept
  double condition_number = 0;
};
// `held`: rho indices held at their start by request; they take no part in the selection.
bool AnalyzeGauge(const BundleData& data, const BundleState& state, const IntrinsicsMask& estimate,
                  double rank_tolerance, Gauge* gauge, const std::vector<int>& held = {});

// Weak directions of the free set `gauge` leaves (BundleOptions::weak_length_tolerance_m): the joint
// parameters these poses determine worse than their tolerance at data.sigma_px, given the columns kept
// before them in SelectionOrder, evaluated at `state` (the nominal model, as the gauge). Returns false
// when the problem cannot be evaluated there.
bool FindWeakParameters(const BundleData& data, const BundleState& state, const Gauge& gauge,
                        const IntrinsicsMask& estimate, double length_tolerance_m, double angle_tolerance_rad,
                        std::vector<identification::WeakColumn>* weak);

}  // namespace selfcal::bundle::internal
