// Building blocks shared by the twoview sources; not part of the module's contract (two_view.h is).
//
// Coordinates: "centred" means CenteredPixel (u - c_x, (v - c_y) / mu), where one focal f_x applies
// to both axes and A = diag(f_x, f_x, 1) (eq. (8) with mu divided out). "normalised" means A^-1 * centred.
// Every distance handed to a threshold is measured in raw pixels, so mu != 1 does not change what a
// pixel threshold means.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "twoview/two_view.h"

namespace selfcal::twoview::internal {

// Relative tolerance on singular values below which a design matrix counts as rank-deficient. Exact
// degeneracies (planar or collinear points, identical images) give ~1e-16; any real noise gives more
// than 1e-6, so the value is not critical.
constexpr double kRankTolerance = 1e-9;

// Unit null vector of a design matrix with >= 9 rows and 9 columns. False when a second null direction
// exists, i.e. the smallest two singular values are both negligible.
template <typename Matrix>
bool DesignNullVector(const Matrix& design, Eigen::Matrix<double, 9, 1>* null) {
  Eigen::JacobiSVD<Matrix> svd(design, Eigen::ComputeFullV);
  const auto& sv = svd.singularValues();
  if (!(sv(7) > kRankTolerance * sv(0))) return false;
  *null = svd.matrixV().col(8);
  return true;
}

// The same for a minimal sample (8 equations): column-pivoted QR of the 9x8 transpose, whose last Q
// column is orthogonal to the row space. Several times cheaper than a 9x9 SVD, which matters in RANSAC.
bool MinimalNullVector(const Eigen::Matrix<double, 8, 9>& design, Eigen::Matrix<double, 9, 1>* null);

// Both images' pixels and centred coordinates, index-aligned.
struct Correspondences {
  std::vector<Eigen::Vector2d> pixels1, pixels2;
  std::vector<Eigen::Vector2d> centred1, centred2;
  int size() const { return static_cast<int>(pixels1.size()); }
};
Correspondences MakeCorrespondences(const CameraIntrinsics& camera, const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2);

// Hartley's normalisation of the listed points (centroid to the origin, mean distance sqrt(2)); false
// when they all coincide. ApplyAffine applies such a scale-and-shift matrix to a point.
bool NormalisingTransform(const std::vector<Eigen::Vector2d>& x, const std::vector<int>& indices, Eigen::Matrix3d* t);
Eigen::Vector2d ApplyAffine(const Eigen::Matrix3d& t, const Eigen::Vector2d& x);

// C with centred = C * pixel (homogeneous).
Eigen::Matrix3d CentringMatrix(const CameraIntrinsics& camera);
// Fundamental / homography in centred coordinates -> the same map in pixels.
Eigen::Matrix3d FundamentalToPixels(const CameraIntrinsics& camera, const Eigen::Matrix3d& f_centred);
Eigen::Matrix3d HomographyToPixels(const CameraIntrinsics& camera, const Eigen::Matrix3d& h_centred);

// Normalised 8-point on the listed correspondences (>= 8). False when the design or the result is
// rank-deficient (then *f is untouched).
bool EightPoint(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
                const std::vector<int>& indices, Eigen::Matrix3d* f);

// Normalised DLT homography x2 ~ H x1 on the listed correspondences (>= 4). False when degenerate.
bool HomographyDlt(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
                   const std::vector<int>& indices, Eigen::Matrix3d* h);

// Squared Sampson distance of x2^T F x1 = 0 (first-order geometric error, units of the coordinates).
double SampsonSquared(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2);
// Signed distances of x2 to the line F x1 (*d2) and of x1 to the line F^T x2 (*d1).
void EpipolarDistances(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2, double* d1,
                       double* d2);
// Squared transfer errors |x2 - H x1|^2 (*e12) and |x1 - H^-1 x2|^2 (*e21); +inf at infinity.
void TransferErrors(const Eigen::Matrix3d& h, const Eigen::Matrix3d& h_inv, const Eigen::Vector2d& x1,
                    const Eigen::Vector2d& x2, double* e12, double* e21);

// Sine of the angle between one optical axis and the epipolar plane containing the other, the smaller of
// the two, given a centred fundamental matrix and a focal. Zero when the axes intersect.
double AxisCoplanaritySine(const Eigen::Matrix3d& f_centred, double fx_px);

struct RansacResult {
  bool found = false;
  Eigen::Matrix3d model = Eigen::Matrix3d::Zero();  // centred coordinates
  std::vector<bool> inliers;
  int num_inliers = 0;
  int iterations = 0;
};
// Fundamental matrix: 8-point samples, inlier when the Sampson distance (px) <= threshold.
RansacResult RansacFundamental(const TwoViewOptions& options, const CameraIntrinsics& camera,
                               const Correspondences& data, std::mt19937_64* rng);
// Homography: 4-point DLT samples, inlier when both transfer errors <= HomographyThresholdPx().
// useful_inlier_ratio: the search may stop once it is confident that no homography explaining this
// fraction of the correspondences was missed (0: the usual adaptive count).
RansacResult RansacHomography(const TwoViewOptions& options, const CameraIntrinsics& camera,
                              const Correspondences& data, double useful_inlier_ratio, std::mt19937_64* rng);
double HomographyThresholdPx(const TwoViewOptions& options);

// ORB-SLAM2-style model scores (truncated chi-square) over all correspondences; see ransac.cc.
double FundamentalScore(const TwoViewOptions& options, const CameraIntrinsics& camera, const Eigen::Matrix3d& f_centred,
                        const Correspondences& data);
double HomographyScore(const TwoViewOptions& options, const CameraIntrinsics& camera, const Eigen::Matrix3d& h_centred,
                       const Correspondences& data);

// Faugeras' SVD decomposition of a homography in normalised coordinates, H ~ R + t n^T: up to 8 (R, t)
// with unit t. Empty when H is (a multiple of) a rotation, for which t = 0 and the plane is undefined.
std::vector<Rigid3> DecomposeHomography(const Eigen::Matrix3d& h_normalised);

// The plane of one decomposition (R, unit t) of a normalised homography h: scaled to a unit middle
// singular value with a positive determinant, h - R = t' n^T; *normal is the unit n turned towards
// `ref_bearing` (the points' side), *t_over_distance the translation in units of the first camera's
// distance to the plane. False when h - R is not of rank one (the decomposition is of -h).
bool PlaneOfDecomposition(const Eigen::Matrix3d& h_normalised, const Eigen::Matrix3d& rotation,
                          const Eigen::Vector3d& ref_bearing, Eigen::Vector3d* normal, Eigen::Vector3d* t_over_distance);

// Cheirality of one candidate: how many listed correspondences triangulate in front of both cameras,
// and how many behind a camera with a triangulation angle of at least min_parallax_rad (for those the
// sign of the depth is not a matter of noise).
struct CheiralityCount {
  int in_front = 0;
  int behind = 0;
};
CheiralityCount CountCheirality(const Rigid3& cam2_from_cam1, const std::vector<Eigen::Vector2d>& n1,
                                const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices,
                                double min_parallax_rad);
inline int CountInFront(const Rigid3& cam2_from_cam1, const std::vector<Eigen::Vector2d>& n1,
                        const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices) {
  return CountCheirality(cam2_from_cam1, n1, n2, indices, 0.0).in_front;
}

// G5: the candidate with the most correspondences in front of both cameras, and whether it is a clear
// winner (the rules are in fundamental.cc). best < 0 when there is no candidate.
struct CheiralityChoice {
  int best = -1;
  bool clear = false;
  int best_in_front = 0;
  int best_behind = 0;
  int runner_up_in_front = 0;  // the strongest rival not ruled out, 0 if none
  int runner_up_behind = 0;
  int runner_up = -1;          // its index, -1 if none
};
CheiralityChoice ChooseByCheirality(const std::vector<Rigid3>& candidates, const std::vector<Eigen::Vector2d>& n1,
                                    const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices,
                                    double min_parallax_rad);

// Eq. (12) over the listed correspondences for E = [t]x R and focal fx: RMS (px) of the symmetric
// epipolar distance sqrt(d1^2 + d2^2).
double RmsSymmetricEpipolarPx(const CameraIntrinsics& camera, double fx_px, const Rigid3& cam2_from_cam1,
                              const Correspondences& data, const std::vector<int>& indices);
Eigen::Matrix3d FundamentalFromPose(double fx_px, const Rigid3& cam2_from_cam1);  // centred coordinates

struct RefineResult {
  bool accepted = false;
  bool failed = false;  // solver failure or non-finite result (G9), as opposed to "nothing to improve"
  double fx_px = 0;
  Rigid3 cam2_from_cam1;
  std::string termination;  // Ceres termination type, snake_case
  std::string detail;       // termination, iterations and costs in words
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
};
// Levenberg-Marquardt on eq. (13) (signed pixel epipolar distances in both images) over 1/f_x (when
// refine_focal), R (quaternion manifold) and the direction of t (sphere manifold), with a Huber loss of
// scale huber_px on sqrt(d1^2 + d2^2). A result whose focal leaves (min_focal_px, max_focal_px) counts as
// failed.
RefineResult RefineEpipolar(const CameraIntrinsics& camera, const Correspondences& data,
                            const std::vector<int>& indices, double fx_px, const Rigid3& cam2_from_cam1,
                            bool refine_focal, int max_iterations, double huber_px, double min_focal_px,
                            double max_focal_px);

// ---- Diagnostics (G6, G10) ----------------------------------------------------------------------

// G6, OpenCV recoverPose's distanceThresh: with |t| = 1 depths are in baselines, and a point deeper than
// this along either camera's axis counts as far.
constexpr double kFarDepthBaselines = 50.0;

// Fraction of the listed correspondences (normalised coordinates) whose (midpoint) triangulation lies
// at least kFarDepthBaselines * |t| deep in either camera, in front or behind (for such a point the sign
// of the depth is noise), or at infinity. 0 for an empty list.
double FarPointFraction(const Rigid3& cam2_from_cam1, const std::vector<Eigen::Vector2d>& n1,
                        const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices);

// G10: score test of a radial distortion k1 = 0 against k1 != 0 (x_d = x (1 + k1 r^2) on normalised
// coordinates, as camera.h), given the fitted f_x and pose. The signed Sampson distances (raw px) of
// the listed correspondences are regressed on their derivative with respect to k1 after projecting out
// their derivatives with respect to 1/f_x, R and the direction of t (central differences): the
// t statistic z of that regression is about N(0, 1) without distortion, whatever the pose, and k1 is
// the Gauss-Newton estimate. This looks at the signed residuals, whose pattern a radial term fixes,
// where |residual| against r^2 does not: f_x and the pose absorb most of a radial distortion, and
// what is left is comparable to the noise in magnitude yet coherent in sign.
struct RadialDistortionScore {
  int n = 0;
  bool observable = false;         // k1 is not a combination of f_x and pose changes here
  double k1 = 0;                   // one Gauss-Newton step from 0, camera.h's convention
  double z = 0;                    // k1 over its standard error (t with n - 7 degrees of freedom)
  double max_displacement_px = 0;  // |k1| r^3 / f_x^2 at the outermost listed point
};
RadialDistortionScore ScoreRadialDistortion(const CameraIntrinsics& camera, double fx_px, const Rigid3& cam2_from_cam1,
                                            const Correspondences& data, const std::vector<int>& indices);

// ---- OpenCV reference (G2) -------------------------------------------------------------------------

// G2: OpenCV's 5-point solver stacks its up to 10 solutions into one 3N x 3 matrix, and recoverPose
// asserts on anything but 3 x 3. This scores each 3 x 3 block of `stacked` (essential matrices for
// known f = camera.fx_px, normalised coordinates) and chooses one explicitly:
//   inliers: correspondences allowed by `mask` (empty: all) whose Sampson distance (raw px) to the
//            candidate is within threshold_px, recomputed here rather than trusted (G8);
//   good:    those of its inliers that cv::recoverPose puts in front of both cameras (and nearer than
//            50 baselines) for its best decomposition.
// The candidate with the most good points wins; ties keep the first. Non-finite or zero blocks are
// skipped. index = -1 with a message when stacked is empty, not 3N x 3 or no candidate has a good point.
struct EssentialChoice {
  int index = -1;
  int num_candidates = 0;
  std::vector<int> num_inliers;                            // per candidate (0 for a skipped one)
  std::vector<int> num_good;                               // per candidate
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // of the winner, cam2_from_cam1
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // unit
  std::vector<bool> good;                                  // per correspondence, the winner's good points
  std::string message;
};
EssentialChoice ChooseEssentialCandidate(const Eigen::MatrixXd& stacked, const CameraIntrinsics& camera,
                                         const std::vector<Eigen::Vector2d>& pixels1,
                                         const std::vector<Eigen::Vector2d>& pixels2, const std::vector<bool>& mask,
                                         double threshold_px);

// Sets the outcome and message of a report and returns it.
inline TwoViewReport Finish(TwoViewReport report, Outcome outcome, const std::string& message) {
  report.outcome = outcome;
  report.message = message;
  return report;
}

// Screens the inputs every estimator shares (options, camera, sizes, D7 finiteness, G1 count). Returns
// true when they are usable; otherwise fills report->outcome and report->message. Sets report->fx_px to
// the prior and report->inliers to all false either way.
bool ScreenInput(const TwoViewOptions& options, const CameraIntrinsics& camera,
                 const std::vector<Eigen::Vector2d>& pixels1, const std::vector<Eigen::Vector2d>& pixels2,
                 TwoViewReport* report);

}  // namespace selfcal::twoview::internal
