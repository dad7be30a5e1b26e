// Task-level two-view estimator: the policy that joins RANSAC, model selection (G4), the pure-rotation
// check (G3), the factor method with cheirality (G5), the refinement (G9), the far-point check (G6) and
// the diagnostics on the final residuals (G10).
#include "twoview/two_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview {

using internal::Finish;

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNotRun:
      return "not_run";
    case Outcome::kSuccess:
      return "success";
    case Outcome::kInvalidInput:
      return "invalid_input";
    case Outcome::kTooFewPoints:
      return "insufficient_points";  // ../shared/RELIABILITY.md G1 names it so
    case Outcome::kDegenerate:
      return "degenerate";
    case Outcome::kPureRotation:
      return "pure_rotation";
    case Outcome::kLowDepthVariation:
      return "low_depth_variation";
    case Outcome::kAmbiguousPose:
      return "ambiguous_pose";
    case Outcome::kTooManyOutliers:
      return "too_many_outliers";
    case Outcome::kNoConvergence:
      return "no_convergence";
  }
  return "unknown";
}

std::string TwoViewOptions::Validate() const {
  std::ostringstream out;
  if (!(ransac_threshold_px > 0) || !std::isfinite(ransac_threshold_px)) {
    out << "ransac_threshold_px = " << ransac_threshold_px << " must be finite and > 0\n";
  }
  if (!(ransac_confidence > 0 && ransac_confidence < 1)) {
    out << "ransac_confidence = " << ransac_confidence << " must lie in (0, 1)\n";
  }
  if (ransac_max_iterations < 1) out << "ransac_max_iterations = " << ransac_max_iterations << " must be >= 1\n";
  if (min_points < 8) out << "min_points = " << min_points << " must be >= 8 (the 8-point algorithm)\n";
  if (!(min_inlier_ratio >= 0 && min_inlier_ratio <= 1)) {
    out << "min_inlier_ratio = " << min_inlier_ratio << " must lie in [0, 1]\n";
  }
  if (!(planar_homography_ratio >= 0 && planar_homography_ratio <= 1)) {
    out << "planar_homography_ratio = " << planar_homography_ratio << " must lie in [0, 1]\n";
  }
  if (!(min_parallax_deg >= 0 && min_parallax_deg < 90)) {
    out << "min_parallax_deg = " << min_parallax_deg << " must lie in [0, 90)\n";
  }
  if (!(max_rotation_excess >= 1) || !std::isfinite(max_rotation_excess)) {
    out << "max_rotation_excess = " << max_rotation_excess << " must be finite and >= 1\n";
  }
  if (!(rotation_excess_floor_px >= 0) || !std::isfinite(rotation_excess_floor_px)) {
    out << "rotation_excess_floor_px = " << rotation_excess_floor_px << " must be finite and >= 0\n";
  }
  if (!(max_far_point_fraction >= 0 && max_far_point_fraction <= 1)) {
    out << "max_far_point_fraction = " << max_far_point_fraction << " must lie in [0, 1]\n";
  }
  if (!(focal_observability_min >= 0 && focal_observability_min < 1)) {
    out << "focal_observability_min = " << focal_observability_min << " must lie in [0, 1)\n";
  }
  if (max_refine_iterations < 0) out << "max_refine_iterations = " << max_refine_iterations << " must be >= 0\n";
  return out.str();
}

namespace {

using internal::Correspondences;

// A focal this far from the prior is a symptom of near-degenerate geometry, not a lens: a linear one is
// replaced by the prior as the refinement's start, a refined one counts as a diverged refinement (G9).
constexpr double kMaxFocalRatio = 10.0;

// G10, inlier ratio: at the noise a RANSAC threshold is chosen for (sigma at most half of it) a correct
// model keeps about 95 % of clean correspondences, so fewer than 80 % means mismatches or a model that
// does not fit, such as wrong intrinsics.
constexpr double kWarnInlierRatio = 0.8;
// G10, radial distortion (internal::ScoreRadialDistortion). The test runs on the correspondences within
// kRadialTestGate times the RANSAC threshold of the final model, not on the inliers only: the outermost
// points, which carry most of a distortion's signature, are the first the RANSAC gate drops, while 3x
// still keeps out gross mismatches. A warning needs
//  - |z| > kRadialTestMinZ (two-sided p = 5e-4 for a Gaussian z). Measured at 0.5 px over 1000 seeded
//    scenes per layout (two_view_diagnostics_test.cc, DISABLED_G10RadialWarningStudy), the 80 points
//    within r < 260 px / filling the image (r < 400 px): clean 0 / 1 warnings, with 10 % random mismatches
//    0 / 2, with 40 % 7 / 1. With k1 = -0.15 left uncorrected: 117 / 299 of 300 warned. Near the
//    centre the distortion moves a point at most 2.6 px and f_x and the pose absorb most of it, so
//    the test has little power there; over the whole image it is reliable;
//  - the implied displacement at the outermost point, |k1| r^3 / f_x^2, of at least
//    kRadialTestMinDisplacement times the RANSAC threshold: a distortion too small to matter at the
//    noise the threshold is set for is not worth a warning, and exact data (residuals that are
//    rounding errors with any z) stay quiet;
//  - at least kRadialTestMinPoints points, so that the t statistic is close to Gaussian.
constexpr double kRadialTestGate = 3.0;
constexpr double kRadialTestMinZ = 3.5;
constexpr double kRadialTestMinDisplacement = 0.25;
constexpr int kRadialTestMinPoints = 30;

void WarnIfFewInliers(int num_inliers, int n, TwoViewReport* report) {
  const double ratio = n > 0 ? static_cast<double>(num_inliers) / n : 0;
  if (ratio >= kWarnInlierRatio) return;
  std::ostringstream m;
  m << "inlier ratio " << ratio << ": outliers or wrong intrinsics (" << num_inliers << " of " << n
    << " correspondences fit the final model, below " << kWarnInlierRatio << ")";
  report->warnings.push_back(m.str());
}

// Correspondences whose Sampson distance (px) to the epipolar geometry of (f_x, pose) is within the gate.
std::vector<int> SampsonInliers(const CameraIntrinsics& camera, double fx_px, const Rigid3& cam2_from_cam1,
                                const Correspondences& data, double threshold_px) {
  const Eigen::Matrix3d f_px =
      internal::FundamentalToPixels(camera, internal::FundamentalFromPose(fx_px, cam2_from_cam1));
  std::vector<int> out;
  for (int i = 0; i < data.size(); ++i) {
    if (internal::SampsonSquared(f_px, data.pixels1[i], data.pixels2[i]) <= threshold_px * threshold_px)
      out.push_back(i);
  }
  return out;
}

void WarnIfRadialDistortion(const TwoViewOptions& options, const CameraIntrinsics& camera, double fx_px,
                            const Rigid3& cam2_from_cam1, const Correspondences& data, TwoViewReport* report) {
  const double gate_px = kRadialTestGate * options.ransac_threshold_px;
  const std::vector<int> tested = SampsonInliers(camera, fx_px, cam2_from_cam1, data, gate_px);
  if (static_cast<int>(tested.size()) < kRadialTestMinPoints) return;
  const internal::RadialDistortionScore score =
      internal::ScoreRadialDistortion(camera, fx_px, cam2_from_cam1, data, tested);
  if (!score.observable || !(std::abs(score.z) > kRadialTestMinZ) ||
      !(score.max_displacement_px >= kRadialTestMinDisplacement * options.ransac_threshold_px)) {
    return;
  }
  std::ostringstream m;
  m << "intrinsics/distortion suspect: residuals grow with radius (a radial term k1 = " << score.k1
    << " explains them with z = " << score.z << ", |z| > " << kRadialTestMinZ << ", over " << score.n
    << " correspondences within " << gate_px << " px; it moves the outermost point by " << score.max_displacement_px
    << " px)";
  report->warnings.push_back(m.str());
}

std::vector<int> IndicesOf(const std::vector<bool>& mask) {
  std::vector<int> out;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

void Normalise(const Correspondences& data, double fx_px, std::vector<Eigen::Vector2d>* n1,
               std::vector<Eigen::Vector2d>* n2) {
  n1->resize(data.size());
  n2->resize(data.size());
  for (int i = 0; i < data.size(); ++i) {
    (*n1)[i] = data.centred1[i] / fx_px;
    (*n2)[i] = data.centred2[i] / fx_px;
  }
}

Eigen::Vector3d Bearing(const Eigen::Vector2d& n) { return Eigen::Vector3d(n.x(), n.y(), 1).normalized(); }

// Rotation that best aligns the rays of view 1 with those of view 2 (Wahba's problem, SVD solution):
// the rotation-only model, exact for a pure rotation.
Eigen::Matrix3d BestRotation(const std::vector<Eigen::Vector2d>& n1, const std::vector<Eigen::Vector2d>& n2,
                             const std::vector<int>& indices) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (int i : indices) m += Bearing(n2[i]) * Bearing(n1[i]).transpose();
  return NearestRotation(m);
}

// Median angle between the ray of view 2 and the rotation-compensated ray of view 1.
double MedianParallaxRad(const Eigen::Matrix3d& r, const std::vector<Eigen::Vector2d>& n1,
                         const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices) {
  std::vector<double> angles;
  angles.reserve(indices.size());
  for (int i : indices) {
    const Eigen::Vector3d a = r * Bearing(n1[i]), b = Bearing(n2[i]);
    angles.push_back(std::atan2(a.cross(b).norm(), a.dot(b)));
  }
  if (angles.empty()) return 0;
  auto mid = angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2);
  std::nth_element(angles.begin(), mid, angles.end());
  return *mid;
}

// Median distance (px, in image 2) between each inlier and its view-1 pixel mapped by the homography h
// (centred coordinates).
double MedianTransferPx(const CameraIntrinsics& camera, const Eigen::Matrix3d& h, const Correspondences& data,
                        const std::vector<int>& indices) {
  std::vector<double> errors;
  errors.reserve(indices.size());
  for (int i : indices) {
    const Eigen::Vector3d mapped = h * Eigen::Vector3d(data.centred1[i].x(), data.centred1[i].y(), 1);
    if (!(mapped.z() > 0)) {
      errors.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const Eigen::Vector2d d = mapped.head<2>() / mapped.z() - data.centred2[i];
    errors.push_back(std::hypot(d.x(), camera.mu * d.y()));  // back to raw pixels
  }
  if (errors.empty()) return std::numeric_limits<double>::infinity();
  auto mid = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
  std::nth_element(errors.begin(), mid, errors.end());
  return *mid;
}

// Both models by RANSAC (G7, G8), then model selection (G4).
struct ModelSelection {
  internal::RansacResult fundamental, homography;
  bool use_homography = false;
  const internal::RansacResult& chosen() const { return use_homography ? homography : fundamental; }
};

// False, with `report` finished, when neither model explains enough of the n correspondences.
bool SelectModel(const TwoViewOptions& options, const CameraIntrinsics& camera, const Correspondences& data, int n,
                 ModelSelection* selection, TwoViewReport* report) {
  std::mt19937_64 rng(options.seed);
  internal::RansacResult& fundamental = selection->fundamental;
  internal::RansacResult& homography = selection->homography;
  fundamental = internal::RansacFundamental(options, camera, data, &rng);
  // The homography only matters if it can win the model selection: with own-gate scores R_H stays below
  // 0.45 unless H explains more than about half of the fundamental inliers (0.52 without noise, more
  // with), so H-RANSAC may stop once it is confident no such plane was missed. On a 3D scene this is
  // ~130 iterations instead of the cap.
  const double useful_h_ratio = fundamental.found ? 0.5 * fundamental.num_inliers / n : 0.0;
  homography = internal::RansacHomography(options, camera, data, useful_h_ratio, &rng);
  if (!fundamental.found && !homography.found) {
    *report = Finish(*report, Outcome::kDegenerate,
                     "every 8-point and 4-point sample is rank-deficient (collinear or coincident points)");
    return false;
  }
  const double score_f = fundamental.found ? internal::FundamentalScore(options, camera, fundamental.model, data) : 0;
  const double score_h = homography.found ? internal::HomographyScore(options, camera, homography.model, data) : 0;
  report->homography_ratio = score_f + score_h > 0 ? score_h / (score_f + score_h) : 0;

  const int most_inliers = std::max(fundamental.num_inliers, homography.num_inliers);
  if (most_inliers < options.min_inlier_ratio * n) {
    std::ostringstream m;
    m << "best model explains " << most_inliers << " of " << n << " correspondences, below the floor "
      << options.min_inlier_ratio << " (fundamental " << fundamental.num_inliers << " inliers after "
      << fundamental.iterations << " iterations, homography " << homography.num_inliers << ")";
    *report = Finish(*report, Outcome::kTooManyOutliers, m.str());
    return false;
  }
  // Without a fundamental matrix (its 8-point design was rank-deficient everywhere) only H remains.
  selection->use_homography =
      !fundamental.found || (homography.found && report->homography_ratio > options.planar_homography_ratio);
  return true;
}

struct FocalChoice {
  double fx_px = 0;
  bool refine = false;  // the refinement estimates f_x
  std::string note;
};

// f_x: Bougnoux from Q when the geometry observes it, else the prior. Sets report->fx_linear_px when
// Bougnoux's value is used.
FocalChoice ChooseFocal(const TwoViewOptions& options, const CameraIntrinsics& camera, const ModelSelection& selection,
                        TwoViewReport* report) {
  FocalChoice focal;
  focal.fx_px = camera.fx_px;
  std::ostringstream note;
  if (selection.use_homography) {
    note << "f_x = prior (a single planar pair does not determine it)";
  } else if (!options.estimate_focal) {
    note << "f_x given";
  } else {
    const Eigen::Matrix3d& q = selection.fundamental.model;
    double f_linear = 0, observability = 0;
    const bool ok = FocalFromFundamental(q, options.focal_observability_min, &f_linear, &observability);
    const bool plausible = ok && f_linear < kMaxFocalRatio * camera.fx_px && f_linear > camera.fx_px / kMaxFocalRatio;
    // The observability of the geometry, judged with the prior focal: noise can make Bougnoux's f^2
    // negative for a pair that does determine f, and then the refinement still should estimate it.
    const double geometric = internal::AxisCoplanaritySine(q, camera.fx_px);
    if (plausible) {
      focal.fx_px = f_linear;
      report->fx_linear_px = f_linear;
      focal.refine = true;
      note << "f_x linear " << f_linear << " px (axis coplanarity sine " << observability << ")";
    } else if (geometric >= options.focal_observability_min) {
      focal.refine = true;
      note << "linear f_x failed (" << (ok ? "implausible" : "f^2 <= 0") << "), refined from the prior "
           << "(axis coplanarity sine " << geometric << ")";
    } else {
      note << "f_x unobservable: optical axes (nearly) intersect, axis coplanarity sine " << geometric << " < "
           << options.focal_observability_min << "; prior used";
    }
  }
  focal.note = note.str();
  return focal;
}

// The pose hypotheses at focal fx: Theorem 1's factors of E = A^T Q A, or the homography decomposition.
std::vector<Rigid3> PoseCandidates(const ModelSelection& selection, double fx) {
  if (selection.use_homography) {
    const Eigen::Matrix3d k = Eigen::Vector3d(fx, fx, 1).asDiagonal();
    return internal::DecomposeHomography(k.inverse() * selection.homography.model * k);
  }
  const Eigen::Matrix3d a = Eigen::Vector3d(fx, fx, 1).asDiagonal();
  return FactorEssential(a.transpose() * selection.fundamental.model * a);
}

// The planar path: the plane (unit normal in cam1, towards the points' side) of the chosen decomposition
// and of the strongest rival, so that a caller with more views of the same plane can choose.
void SetPlanes(const ModelSelection& selection, double fx, const std::vector<Rigid3>& candidates,
               const internal::CheiralityChoice& choice, const std::vector<Eigen::Vector2d>& n1,
               const std::vector<int>& inliers, TwoViewReport* report) {
  const Eigen::Matrix3d k = Eigen::Vector3d(fx, fx, 1).asDiagonal();
  const Eigen::Matrix3d h = k.inverse() * selection.homography.model * k;
  Eigen::Vector3d bearing = Eigen::Vector3d::Zero();
  for (int i : inliers) bearing += Eigen::Vector3d(n1[i].x(), n1[i].y(), 1).normalized();
  Eigen::Vector3d t;
  if (choice.best >= 0) {
    report->has_plane =
        internal::PlaneOfDecomposition(h, candidates[choice.best].rotation, bearing, &report->plane_normal, &t);
  }
  if (choice.runner_up >= 0) {
    report->has_rival_plane = internal::PlaneOfDecomposition(h, candidates[choice.runner_up].rotation, bearing,
                                                             &report->rival_plane_normal, &t);
  }
}

// G3 (a): the rotation-only model, a Wahba fit of the rays with the prior focal (Bougnoux's f means
// nothing for a rotation), and its median transfer error over the inliers (px). If it is within the
// homography gate, a translation is not needed to explain the data, so it is not observable: this
// catches pure rotations, where t is noise and cheirality a coin toss. The residual is compared with the
// noise gate, not with min_parallax_deg: it is what is left after a rotation has absorbed most of a real
// translation's flow (about 1 deg in the 17 deg test scene, 0.3 deg for a lateral motion over a plane),
// small in angle yet far above the noise. (G3 (b), the parallax of the refined pose, comes later.)
// A rotation also has to fit about as well as a general homography on the same inliers: with a lens
// model error (real images) both leave a residual near the gate, and a real translation then shows only
// as the rotation's excess over the homography's residual.
struct RotationOnlyFit {
  Eigen::Matrix3d rotation;
  double residual_px = 0;
  double homography_residual_px = 0;  // of the DLT homography on the inliers (infinite if none)
};

RotationOnlyFit FitRotationOnly(const CameraIntrinsics& camera, const Correspondences& data,
                                const std::vector<int>& inliers) {
  std::vector<Eigen::Vector2d> p1, p2;
  Normalise(data, camera.fx_px, &p1, &p2);
  RotationOnlyFit fit;
  fit.rotation = BestRotation(p1, p2, inliers);
  const Eigen::Matrix3d k = Eigen::Vector3d(camera.fx_px, camera.fx_px, 1).asDiagonal();
  fit.residual_px = MedianTransferPx(camera, k * fit.rotation * k.inverse(), data, inliers);
  Eigen::Matrix3d h;
  fit.homography_residual_px = internal::HomographyDlt(data.centred1, data.centred2, inliers, &h)
                                   ? MedianTransferPx(camera, h, data, inliers)
                                   : std::numeric_limits<double>::infinity();
  return fit;
}

struct RefinementResult {
  Outcome outcome = Outcome::kSuccess;  // kNoConvergence when the first round failed (G9)
  std::string note;
};

// Refinement of eq. (13) (G9) of (fx, pose) on `inliers`, which it updates, as it does the report's
// inlier set and refinement fields, and n1, n2 (normalised with the final focal).
RefinementResult RefinePose(const TwoViewOptions& options, const CameraIntrinsics& camera, const Correspondences& data,
                            bool use_homography, bool refine_focal, double* fx, Rigid3* pose,
                            std::vector<int>* inliers, std::vector<Eigen::Vector2d>* n1,
                            std::vector<Eigen::Vector2d>* n2, TwoViewReport* report) {
  RefinementResult result;
  result.note = options.refine ? "" : "not refined";
  if (!options.refine) return result;
  if (use_homography) {
    // Eq. (13) ignores the plane and is poorly conditioned on planar points: in tests it doubled the
    // error of the homography decomposition, so the planar path keeps the decomposition.
    report->refinement_termination = "skipped";
    result.note = "not refined (homography path: eq. (13) would discard the plane)";
    return result;
  }
  // Up to two rounds, the second on the inliers of the refined model (local optimisation): the RANSAC
  // gate was applied with an 8-point model, which loses some inliers and keeps an occasional outlier. Huber's
  // quadratic zone covers the gate (for a true inlier sqrt(d1^2 + d2^2) is about twice its Sampson distance).
  const double huber_px = 2 * options.ransac_threshold_px;
  for (int round = 0; round < 2; ++round) {
    const internal::RefineResult refined =
        internal::RefineEpipolar(camera, data, *inliers, *fx, *pose, refine_focal, options.max_refine_iterations,
                                 huber_px, camera.fx_px / kMaxFocalRatio, camera.fx_px * kMaxFocalRatio);
    report->refinement_termination = refined.termination;
    report->refinement_iterations += refined.iterations;
    result.note += (round == 0 ? "refinement " : "; on the updated inliers ") + refined.detail;
    if (!refined.accepted) {
      // G9: a failure of the first round keeps the linear estimate, flagged; of the second, the first
      // round's result.
      if (refined.failed && round == 0) result.outcome = Outcome::kNoConvergence;
      result.note += refined.failed ? " (rejected)" : " (no decrease)";
      break;
    }
    report->refinement_accepted = true;
    *fx = refined.fx_px;
    *pose = refined.cam2_from_cam1;
    const std::vector<int> updated = SampsonInliers(camera, *fx, *pose, data, options.ransac_threshold_px);
    if (updated == *inliers || static_cast<int>(updated.size()) < options.min_points) break;
    *inliers = updated;
  }
  if (result.outcome == Outcome::kNoConvergence) result.note += ": linear estimate kept";
  // Eq. (13) is even in t; the sign is fixed by cheirality again.
  Normalise(data, *fx, n1, n2);
  const Rigid3 flipped(pose->rotation, -pose->translation);
  if (internal::CountInFront(flipped, *n1, *n2, *inliers) > internal::CountInFront(*pose, *n1, *n2, *inliers)) {
    *pose = flipped;
  }
  report->inliers.assign(data.size(), false);
  for (int i : *inliers) report->inliers[i] = true;
  report->num_inliers = static_cast<int>(inliers->size());
  return result;
}

// G3 (b) before G6: pure-rotation detection has priority. A point farther than 50 baselines has a
// triangulation angle below 1/50 rad (1.15 deg), so when more than half of the inliers are far the
// median parallax is below 1.15 deg too: with the default min_parallax_deg of 1, G6 is left the pairs
// in the 1-1.15 deg band (near points and noise can put them there), and everything once
// min_parallax_deg is lowered. In both the rotation stands and the direction of t is too weakly
// determined to hand out. `outcome` is the refinement's: only a success is judged. Returns the final
// outcome, its message in *message.
Outcome JudgeParallaxAndDepth(const TwoViewOptions& options, Outcome outcome, double parallax_deg,
                              const std::string& summary, TwoViewReport* report, std::string* message) {
  if (outcome == Outcome::kSuccess && parallax_deg < options.min_parallax_deg) {
    report->translation_observable = false;
    report->translation_direction.setZero();
    *message = "rotation only: median parallax below " + std::to_string(options.min_parallax_deg) +
               " deg, translation unobservable; " + summary;
    return Outcome::kPureRotation;
  }
  if (outcome == Outcome::kSuccess && report->far_point_fraction > options.max_far_point_fraction) {
    report->translation_observable = false;
    report->translation_direction.setZero();
    std::ostringstream m;
    m << "low depth variation: " << 100 * report->far_point_fraction << " % of the inliers lie farther than "
      << internal::kFarDepthBaselines << " baselines (limit " << 100 * options.max_far_point_fraction
      << " %), translation direction unreliable; " << summary;
    *message = m.str();
    return Outcome::kLowDepthVariation;
  }
  *message = summary;
  return outcome;
}

}  // namespace

bool internal::ScreenInput(const TwoViewOptions& options, const CameraIntrinsics& camera,
                           const std::vector<Eigen::Vector2d>& pixels1, const std::vector<Eigen::Vector2d>& pixels2,
                           TwoViewReport* report) {
  report->fx_px = camera.fx_px;
  const std::string problems = options.Validate() + camera.Validate();
  if (!problems.empty()) {
    *report = Finish(*report, Outcome::kInvalidInput, "invalid options or camera:\n" + problems);
    return false;
  }
  if (pixels1.size() != pixels2.size()) {
    std::ostringstream m;
    m << "correspondence size mismatch: " << pixels1.size() << " pixels in view 1, " << pixels2.size() << " in view 2";
    *report = Finish(*report, Outcome::kInvalidInput, m.str());
    return false;
  }
  for (size_t i = 0; i < pixels1.size(); ++i) {
    if (!pixels1[i].allFinite() || !pixels2[i].allFinite()) {
      *report = Finish(*report, Outcome::kInvalidInput, "non-finite pixel at correspondence " + std::to_string(i) + "");
      return false;
    }
  }
  const int n = static_cast<int>(pixels1.size());
  report->inliers.assign(n, false);
  if (n < options.min_points) {
    std::ostringstream m;
    m << n << " correspondences, at least " << options.min_points << " needed";
    *report = Finish(*report, Outcome::kTooFewPoints, m.str());
    return false;
  }
  return true;
}

TwoViewReport EstimateTwoView(const TwoViewOptions& options, const CameraIntrinsics& camera,
                              const std::vector<Eigen::Vector2d>& pixels1,
                              const std::vector<Eigen::Vector2d>& pixels2) {
  TwoViewReport report;
  if (!internal::ScreenInput(options, camera, pixels1, pixels2, &report)) return report;
  const int n = static_cast<int>(pixels1.size());

  const Correspondences data = internal::MakeCorrespondences(camera, pixels1, pixels2);
  ModelSelection selection;
  if (!SelectModel(options, camera, data, n, &selection, &report)) return report;
  const bool use_homography = selection.use_homography;
  const internal::RansacResult& chosen = selection.chosen();
  report.inliers = chosen.inliers;
  report.num_inliers = chosen.num_inliers;
  std::vector<int> inliers = IndicesOf(chosen.inliers);
  // Every outcome from here on has a final inlier set, so G10's inlier-ratio check applies to all.
  auto finish = [&](Outcome outcome, const std::string& message) {
    WarnIfFewInliers(report.num_inliers, n, &report);
    return Finish(report, outcome, message);
  };
  if (chosen.num_inliers < options.min_points) {
    std::ostringstream m;
    m << chosen.num_inliers << " inliers, at least " << options.min_points << " needed";
    return finish(Outcome::kTooFewPoints, m.str());
  }

  const FocalChoice focal = ChooseFocal(options, camera, selection, &report);
  double fx = focal.fx_px;
  report.fx_px = fx;
  report.planar = use_homography;

  // ---- Candidates (Theorem 1, or the homography decomposition) and cheirality (G5) ----
  std::vector<Eigen::Vector2d> n1, n2;
  Normalise(data, fx, &n1, &n2);
  const std::vector<Rigid3> candidates = PoseCandidates(selection, fx);
  // Depth signs count only for points whose triangulation angle exceeds what two threshold-sized pixel
  // errors can produce.
  const double sign_parallax_rad = 2 * options.ransac_threshold_px / fx;
  const internal::CheiralityChoice choice =
      internal::ChooseByCheirality(candidates, n1, n2, inliers, sign_parallax_rad);

  // ---- G3: pure rotation or tiny baseline ----
  // Two signs, either suffices: (a) the rotation-only model explains the inliers (FitRotationOnly);
  // (b) the cheirality winner's median triangulation angle (the angle between the ray of view 2 and the
  // rotated ray of view 1, ORB-SLAM2's parallax) is below min_parallax_deg, checked after the
  // refinement. R is the refined pose's there: a best-fit rotation would absorb the translation's flow,
  // an error as large as the parallax itself.
  const RotationOnlyFit rotation_only = FitRotationOnly(camera, data, inliers);
  std::ostringstream summary;
  summary << (use_homography ? "homography" : "fundamental") << " path, " << report.num_inliers << "/" << n
          << " inliers, R_H " << report.homography_ratio << ", rotation-only residual " << rotation_only.residual_px
          << " px (homography " << rotation_only.homography_residual_px << " px); " << focal.note;
  if (rotation_only.residual_px <= internal::HomographyThresholdPx(options) &&
      rotation_only.residual_px <= options.max_rotation_excess * rotation_only.homography_residual_px +
                                       options.rotation_excess_floor_px) {
    report.rotation = rotation_only.rotation;
    report.translation_observable = false;
    report.translation_direction.setZero();
    report.fx_observable = false;  // f_x is not estimated when a rotation explains the pair
    report.fx_px = camera.fx_px;
    report.fx_linear_px = 0;
    return finish(Outcome::kPureRotation,
                  "rotation only: a rotation alone explains the inliers within the noise gate, translation "
                  "unobservable; " +
                      summary.str());
  }
  if (candidates.empty()) {
    return finish(
        Outcome::kDegenerate,
        "the homography decomposes with no translation, yet no rotation explains the inliers; " + summary.str());
  }
  Rigid3 pose = candidates[choice.best];
  report.rotation = pose.rotation;
  report.translation_direction = pose.translation;
  if (use_homography) SetPlanes(selection, fx, candidates, choice, n1, inliers, &report);
  if (!choice.clear) {
    if (choice.runner_up >= 0) {
      report.has_rival = true;
      report.rival_rotation = candidates[choice.runner_up].rotation;
      report.rival_translation_direction = candidates[choice.runner_up].translation.normalized();
    }
    std::ostringstream m;
    m << "no clear cheirality winner: best candidate has " << choice.best_in_front << " points in front ("
      << choice.best_behind << " clearly behind), strongest rival " << choice.runner_up_in_front << " ("
      << choice.runner_up_behind << "); " << summary.str();
    return finish(Outcome::kAmbiguousPose, m.str());
  }
  report.translation_observable = true;

  const RefinementResult refinement = RefinePose(options, camera, data, use_homography, focal.refine, &fx, &pose,
                                                 &inliers, &n1, &n2, &report);
  const Outcome outcome = refinement.outcome;
  // Observable means estimated from this pair (by Bougnoux and/or an accepted refinement), not the prior.
  report.fx_observable = focal.refine && (report.refinement_accepted || report.fx_linear_px > 0);
  report.fx_px = fx;
  report.rotation = pose.rotation;
  report.translation_direction = pose.translation.normalized();
  report.rms_epipolar_px = internal::RmsSymmetricEpipolarPx(camera, fx, pose, data, inliers);
  const double parallax_deg = RadToDeg(MedianParallaxRad(pose.rotation, n1, n2, inliers));
  report.far_point_fraction = internal::FarPointFraction(pose, n1, n2, inliers);
  WarnIfRadialDistortion(options, camera, fx, pose, data, &report);
  summary << "; median parallax " << parallax_deg << " deg, " << 100 * report.far_point_fraction
          << " % of inliers farther than " << internal::kFarDepthBaselines << " baselines; " << refinement.note;
  std::string message;
  const Outcome final_outcome = JudgeParallaxAndDepth(options, outcome, parallax_deg, summary.str(), &report, &message);
  return finish(final_outcome, message);
}

}  // namespace selfcal::twoview
