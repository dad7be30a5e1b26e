// Naming by prediction at a settled pose (session_runner.h, "Identities at a settled pose"): the dots of
// the accepted samples are predicted at the capture's joints (dot_prediction.h), the raw predictions
// corrected on the dots tracking carried into the frame (or, without them, by votes), the tracked dots
// checked against their gates, and the detections nobody tracked named by gated nearest prediction with
// the ambiguity test (tracking/predicted_match.h), or kept as candidates of dots seen once.
#include <map>

#include <Eigen/Eigenvalues>

#include "acquisition/session_runner_internal.h"

namespace selfcal::acquisition::internal {

std::vector<ViewedSample> Runner::AcceptedSamples() const {
  std::vector<ViewedSample> samples;
  Result<session::SessionLog> log = session::ReadSessionLog(c_.session->journal().records());
  if (!log.ok()) return samples;
  for (const std::optional<session::AcceptedSample>& a : log->accepted) {
    if (!a) continue;
    ViewedSample s;
    s.joints_rad = Eigen::Map<const Eigen::VectorXd>(a->joints_rad.data(), static_cast<Eigen::Index>(a->joints_rad.size()));
    for (const session::SampleDot& d : a->dots) s.dots_px[d.id] = {d.u_px, d.v_px};
    for (const session::SampleDot& d : a->candidates) s.candidates_px[d.id] = {d.u_px, d.v_px};
    samples.push_back(std::move(s));
  }
  return samples;
}

namespace {

// The correction of the raw predictions: from the tracked dots when there are enough, else by votes.
tracking::PredictionCorrection Correction(const std::vector<tracking::PredictedDot>& predicted,
                                          const std::map<int, Eigen::Vector2d>& anchor_px,
                                          const std::vector<tracking::PreviousDot>& tracked,
                                          const std::vector<Eigen::Vector2d>& detections,
                                          const tracking::PredictionCorrectionOptions& options) {
  std::vector<Eigen::Vector2d> from, to;
  for (const tracking::PreviousDot& d : tracked) {
    if (const auto it = anchor_px.find(d.id); it != anchor_px.end()) {
      from.push_back(it->second);
      to.push_back(d.centroid_px);
    }
  }
  if (from.size() >= 3) {
    tracking::PredictionCorrection c = tracking::FitPredictionCorrection(from, to, options);
    if (c.ok) return c;
  }
  return tracking::VotePredictionCorrection(predicted, detections, options);
}

}  // namespace

void Runner::NameByPrediction(const Capture& capture) {
  candidates_.clear();
  const std::vector<ViewedSample> samples = AcceptedSamples();
  if (samples.empty()) return;
  std::map<int, Eigen::Vector2d> tracked_px;
  for (const tracking::PreviousDot& d : tracked_) tracked_px[d.id] = d.centroid_px;
  const DotPredictionReport predicted =
      PredictDots(*c_.prediction, samples, capture.joints.position_rad, tracked_px, o_.prediction);
  if (predicted.dots.empty()) return;
  const tracking::DetectionReport detected = tracking::DetectDots(capture.frame.image, o_.detector);
  std::vector<Eigen::Vector2d> centroids;
  for (const tracking::DotDetection& d : detected.dots) centroids.push_back(d.centroid_px);
  const tracking::PredictionCorrection correction =
      Correction(predicted.dots, predicted.anchor_px, tracked_, centroids, o_.prediction_correction);
  if (!correction.ok) {
    ++report_.prediction_uncorrected;
    Log("prediction: no correction of the nominal predictions (" + correction.message + "): tracked dots only");
    return;
  }
  Log("prediction: " + std::to_string(predicted.dots.size()) + " dots predicted, " +
      std::to_string(tracked_.size()) + " tracked, correction " + correction.message);
  std::vector<tracking::PredictedDot> gates;
  std::map<int, size_t> gate_of;
  for (const tracking::PredictedDot& p : predicted.dots) {
    gate_of[p.id] = gates.size();
    gates.push_back(correction.Apply(p));
  }
  // Gates too long to name (a dot seen once, anywhere over the scene's depth range) doubt no tracked dot,
  // but they compete: a detection in one of them is never given another dot's id.
  std::vector<tracking::PredictedDot> usable;
  std::map<int, double> gate_sigma;  // along the gate's longest axis
  for (const tracking::PredictedDot& g : gates) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(g.cov_px2);
    gate_sigma[g.id] = std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
    if (gate_sigma[g.id] <= o_.prediction.max_gate_sigma_px) usable.push_back(g);
  }
  // Tracked dots far outside their gate are dropped (never recorded under a doubtful id), and so are
  // those that also lie in the gate of a dot not accounted for by another tracked dot in its own gate
  // (a tracker that jumped onto a neighbour along a long epipolar gate).
  auto in_gate = [&](int id, const Eigen::Vector2d& uv) {
    const auto it = gate_of.find(id);
    return it != gate_of.end() && tracking::Mahalanobis2(gates[it->second], uv) <= o_.predicted_match.gate_chi2;
  };
  std::map<int, bool> accounted;
  for (const tracking::PreviousDot& d : tracked_) accounted[d.id] = in_gate(d.id, d.centroid_px);
  std::vector<tracking::PreviousDot> kept;
  for (const tracking::PreviousDot& d : tracked_) {
    bool doubtful = gate_of.count(d.id) && !accounted[d.id];
    for (const tracking::PredictedDot& g : usable) {
      doubtful = doubtful || (g.id != d.id && !accounted[g.id] && in_gate(g.id, d.centroid_px));
    }
    if (doubtful) {
      ++report_.dropped_by_prediction;
      continue;
    }
    kept.push_back(d);
  }
  // Detections on a kept tracked dot are taken; the others are named by prediction, every gate competing
  // and every detection counted (one on a tracked dot in another's gate makes that gate ambiguous). A
  // detection alone in a gate too long to name becomes a candidate (dot_prediction.h).
  std::vector<size_t> free;
  for (size_t k = 0; k < detected.dots.size(); ++k) {
    bool taken = false;
    for (const tracking::PreviousDot& d : kept) {
      taken = taken || (d.centroid_px - centroids[k]).norm() < o_.detector.duplicate_distance_px;
    }
    if (!taken) free.push_back(k);
  }
  const tracking::PredictedMatch match = tracking::MatchPredictions(gates, centroids, o_.predicted_match);
  report_.ambiguous_by_prediction += match.ambiguous;
  for (size_t f = 0; f < free.size(); ++f) {
    const int id = match.id_of_detection[free[f]];
    if (id < 0) continue;
    bool known = false;
    for (const tracking::PreviousDot& d : kept) known = known || d.id == id;
    if (known) continue;  // its tracked blob is elsewhere in the gate: keep the tracked one
    if (gate_sigma[id] > o_.prediction.max_gate_sigma_px) {
      if (gate_sigma[id] <= o_.prediction.max_candidate_gate_sigma_px) {
        candidates_.push_back(tracking::MakePreviousDot(id, detected.dots[free[f]]));
      }
      continue;
    }
    kept.push_back(tracking::MakePreviousDot(id, detected.dots[free[f]]));
    ++report_.named_by_prediction;
  }
  tracked_ = std::move(kept);
}

}  // namespace selfcal::acquisition::internal
