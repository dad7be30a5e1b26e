#include "acquisition/late_naming.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Eigenvalues>

namespace selfcal::acquisition {
namespace {

// The predictions of every dot in `sample`'s frame from `others`, corrected on the dots the sample holds;
// empty when too few of them are predicted or the correction fails. *sigma: each gate's std along its
// longest axis.
std::vector<tracking::PredictedDot> CorrectedGates(const PredictionModel& model, const std::vector<ViewedSample>& others,
                                                   const ViewedSample& sample, const LateNamingOptions& options,
                                                   std::vector<double>* sigma) {
  const DotPredictionReport predicted =
      PredictDots(model, others, sample.joints_rad, sample.dots_px, options.prediction);
  std::vector<Eigen::Vector2d> from, to;
  for (const auto& [id, px] : sample.dots_px) {
    if (const auto it = predicted.anchor_px.find(id); it != predicted.anchor_px.end()) {
      from.push_back(it->second);
      to.push_back(px);
    }
  }
  if (static_cast<int>(from.size()) < options.min_anchors) return {};
  const tracking::PredictionCorrection correction = tracking::FitPredictionCorrection(from, to, options.correction);
  if (!correction.ok) return {};
  std::vector<tracking::PredictedDot> gates;
  sigma->clear();
  for (const tracking::PredictedDot& p : predicted.dots) {
    gates.push_back(correction.Apply(p));
    sigma->push_back(GateSigmaPx(gates.back()));
  }
  return gates;
}

std::map<int, int> SeenBy(const std::vector<ViewedSample>& samples) {
  std::map<int, int> seen_by;  // dot id -> samples holding it
  for (const ViewedSample& s : samples) {
    for (const auto& [id, px] : s.dots_px) ++seen_by[id];
  }
  return seen_by;
}

bool NearAny(const std::map<int, Eigen::Vector2d>& held, const Eigen::Vector2d& uv, double distance_px) {
  for (const auto& [id, px] : held) {
    if ((px - uv).norm() < distance_px) return true;
  }
  return false;
}

}  // namespace

double GateSigmaPx(const tracking::PredictedDot& gate) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(gate.cov_px2);
  return std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
}

LateNaming NameLater(const PredictionModel& model, const std::vector<ViewedSample>& others,
                     const ViewedSample& sample, const tracking::DetectionReport& detected,
                     const LateNamingOptions& options) {
  LateNaming out;
  std::map<int, int> seen_by = SeenBy(others);  // dot id -> other samples holding it
  std::vector<double> sigma;
  std::vector<tracking::PredictedDot> gates = CorrectedGates(model, others, sample, options, &sigma);
  if (gates.empty()) return out;
  out.corrected = true;
  // Every gate competes; only a short gate of a dot the sample lacks, seen by enough others, names.
  std::map<int, bool> naming_id;
  const std::map<int, Eigen::Vector2d>& held = sample.dots_px;
  for (size_t j = 0; j < gates.size(); ++j) {
    tracking::PredictedDot& g = gates[j];
    const bool missing = held.count(g.id) == 0;
    g.names = g.names && sigma[j] <= options.prediction.max_gate_sigma_px &&
              (!missing || seen_by[g.id] >= options.min_other_samples);
    if (missing && g.names) naming_id[g.id] = true;
  }
  std::vector<Eigen::Vector2d> centroids;
  for (const tracking::DotDetection& d : detected.dots) centroids.push_back(d.centroid_px);
  const tracking::PredictedMatch match = tracking::MatchPredictions(gates, centroids, options.match);
  out.ambiguous = match.ambiguous;
  for (size_t k = 0; k < centroids.size(); ++k) {
    const int id = match.id_of_detection[k];
    if (id < 0 || !naming_id[id] || NearAny(held, centroids[k], options.duplicate_distance_px)) continue;
    out.named.push_back(tracking::MakePreviousDot(id, detected.dots[k]));
    naming_id[id] = false;  // one detection per dot
  }
  return out;
}

}  // namespace selfcal::acquisition
