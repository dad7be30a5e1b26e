// Naming detections by predicted positions (issue 12 item 1; ../shared/RELIABILITY.md D4): each known dot has a
// predicted pixel with a 2x2 covariance (from the session's 3-D prediction, acquisition/dot_prediction.h),
// and a detection takes the id of the one prediction whose chi-square gate holds it, when no other dot's
// gate holds it and no other detection lies in that prediction's gate. A dot may have several gates (a
// short one that names and a long one that only competes): they never compete with each other. Never a
// wrong identity rather than a missing one: every ambiguity leaves both sides unnamed.
//
// The raw predictions of a nominal model are off by several pixels, mostly a smooth image-wide offset.
// FitPredictionCorrection estimates that offset from anchors (dots whose identity is known in the frame:
// tracked through the move) as a robust planar map from predicted to observed pixels, and the scatter
// left around it, which the gates then include. Without anchors, it finds a translation by voting over
// prediction-detection pairs and keeps it only when one translation is clearly supported by many dots.
//
// Pixels as dot_detector.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace selfcal::tracking {

struct PredictedDot {
  int id = -1;
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov_px2 = Eigen::Matrix2d::Identity();  // of the prediction (noise + triangulation)
  // False: the gate competes (a detection in it is never given another dot's id) but names nothing, as a
  // gate too long to name. A dot may have several gates: they never compete with each other.
  bool names = true;
};

struct PredictionCorrectionOptions {
  double inlier_threshold_px = 4.0;    // anchors farther from the corrected prediction are outliers
  int min_anchors_affine = 6;          // fewer inliers: a translation only
  double min_model_sigma_px = 0.3;     // floor of the model-error scatter
  double fallback_model_sigma_px = 2.0;  // the scatter assumed when too few anchors measure it
  // Without anchors: translations up to this far are tried; one needs this many supporting dots (and
  // this fraction of the predictions that have a detection nearby), and the second-best translation
  // (more than `vote_radius_px` away) must have at most half its support.
  double vote_search_px = 40.0;
  double vote_radius_px = 2.0;
  int min_vote_support = 6;
  double min_vote_fraction = 0.5;
  std::uint64_t seed = 1;
};

struct PredictionCorrection {
  bool ok = false;
  std::string message;                  // why not, when !ok; how, when ok
  Eigen::Matrix3d observed_from_predicted = Eigen::Matrix3d::Identity();
  Eigen::Matrix2d model_cov_px2 = Eigen::Matrix2d::Zero();  // scatter of the anchors around the map
  int anchors = 0;
  int inliers = 0;
  bool from_votes = false;              // found without anchors
  // The corrected prediction: mapped, covariance plus the model scatter.
  PredictedDot Apply(const PredictedDot& p) const;
};

// The correction from anchors: `predicted[k]` and `observed[k]` belong to the same dot.
PredictionCorrection FitPredictionCorrection(const std::vector<Eigen::Vector2d>& predicted,
                                             const std::vector<Eigen::Vector2d>& observed,
                                             const PredictionCorrectionOptions& options);

// The correction without anchors, by voting over translations between `predictions` and `detections`.
PredictionCorrection VotePredictionCorrection(const std::vector<PredictedDot>& predictions,
                                              const std::vector<Eigen::Vector2d>& detections,
                                              const PredictionCorrectionOptions& options);

// Squared Mahalanobis distance of `uv_px` from the prediction (infinite for a singular covariance).
double Mahalanobis2(const PredictedDot& prediction, const Eigen::Vector2d& uv_px);

struct PredictedMatchOptions {
  double gate_chi2 = 13.8;  // 2 dof, 99.9 %
};

struct PredictedMatch {
  std::vector<int> id_of_detection;  // per detection: the id it is named, or -1
  std::vector<int> gates_of_detection;  // per detection: how many dots' gates hold it
  int named = 0;
  int ambiguous = 0;       // detections left unnamed because two gates or two detections compete
  int outside_gates = 0;   // detections in no gate
};

// Gated nearest prediction with the ambiguity test of the header comment.
PredictedMatch MatchPredictions(const std::vector<PredictedDot>& predictions,
                                const std::vector<Eigen::Vector2d>& detections, const PredictedMatchOptions& options);

}  // namespace selfcal::tracking
