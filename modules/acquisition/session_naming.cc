// Naming by prediction at a settled pose (session_runner.h, "Identities at a settled pose"): the dots of
// the accepted samples are predicted at the capture's joints (dot_prediction.h), the raw predictions
// corrected on the dots tracking carried into the frame (or, without them, by votes), the tracked dots
// checked against their gates, and the detections nobody tracked named by gated nearest prediction with
// the ambiguity test (tracking/predicted_match.h), or kept as candidates of dots seen once.
#include <map>
#include <set>

#include "acquisition/bundled_cameras.h"
#include "acquisition/late_naming.h"
#include "acquisition/seen_once.h"
#include "acquisition/session_runner_internal.h"
#include "base/atomic_file.h"
#include "capture/png_codec.h"

namespace selfcal::acquisition::internal {

std::vector<ViewedSample> Runner::AcceptedSamples() {
  if (!viewed_) {
    viewed_.emplace();
    Result<session::SessionLog> log = session::ReadSessionLog(c_.session->journal().records());
    if (!log.ok()) return {};
    for (size_t pose = 0; pose < log->accepted.size(); ++pose) {
      const std::optional<session::AcceptedSample>& a = log->accepted[pose];
      if (!a) continue;
      ViewedSample& s = (*viewed_)[static_cast<int>(pose)];
      s.joints_rad = Eigen::Map<const Eigen::VectorXd>(a->joints_rad.data(), static_cast<Eigen::Index>(a->joints_rad.size()));
      for (const session::SampleDot& d : a->dots) s.dots_px[d.id] = {d.u_px, d.v_px};
      for (const session::SampleDot& d : a->candidates) s.candidates_px[d.id] = {d.u_px, d.v_px};
    }
  }
  std::vector<ViewedSample> samples;
  for (const auto& [pose, s] : *viewed_) samples.push_back(s);
  return samples;
}

void Runner::RememberSample(int pose, const Eigen::VectorXd& joints_rad, const std::vector<tracking::PreviousDot>& dots,
                            const std::vector<tracking::PreviousDot>& candidates) {
  if (!viewed_) return;  // read from the journal, this sample included, when first asked for
  ViewedSample& s = (*viewed_)[pose];
  s = ViewedSample();
  s.joints_rad = joints_rad;
  for (const tracking::PreviousDot& d : dots) s.dots_px[d.id] = d.centroid_px;
  for (const tracking::PreviousDot& d : candidates) s.candidates_px[d.id] = d.centroid_px;
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
  std::vector<ViewedSample> samples = AcceptedSamples();
  if (samples.empty()) return;
  std::map<int, Eigen::Vector2d> tracked_px;
  for (const tracking::PreviousDot& d : tracked_) tracked_px[d.id] = d.centroid_px;
  // The samples' cameras and f_x as their images give them (bundled_cameras.h), when three or more.
  PredictionModel model = *c_.prediction;
  UseBundledCameras(BundleSampleCameras(model, samples, o_.prediction), &model, &samples);
  const DotPredictionReport predicted =
      PredictDots(model, samples, capture.joints.position_rad, tracked_px, o_.prediction);
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
  // Gates too long to name (a dot seen once, anywhere over the scene's depth range) name nothing and
  // doubt no tracked dot, but they compete: a detection in one of them is never given another dot's id.
  std::vector<tracking::PredictedDot> gates, naming;
  std::vector<double> gate_sigma;  // along the gate's longest axis
  for (const tracking::PredictedDot& p : predicted.dots) {
    gates.push_back(correction.Apply(p));
    gate_sigma.push_back(GateSigmaPx(gates.back()));
    gates.back().names = p.names && gate_sigma.back() <= o_.prediction.max_gate_sigma_px;
    if (gates.back().names) naming.push_back(gates.back());
  }
  auto in_gate = [&](const tracking::PredictedDot& g, const Eigen::Vector2d& uv) {
    return tracking::Mahalanobis2(g, uv) <= o_.predicted_match.gate_chi2;
  };
  // Tracked dots far outside their gates are dropped (never recorded under a doubtful id), and so are
  // those that also lie in the gate of a dot not accounted for by another tracked dot in its own gate
  // (a tracker that jumped onto a neighbour along a long epipolar gate).
  std::map<int, bool> predicted_id, accounted;
  for (const tracking::PredictedDot& g : gates) predicted_id[g.id] = true;
  for (const tracking::PreviousDot& d : tracked_) {
    for (const tracking::PredictedDot& g : gates) accounted[d.id] = accounted[d.id] || (g.id == d.id && in_gate(g, d.centroid_px));
  }
  std::vector<tracking::PreviousDot> kept;
  for (const tracking::PreviousDot& d : tracked_) {
    bool doubtful = predicted_id[d.id] && !accounted[d.id];
    for (const tracking::PredictedDot& g : naming) {
      doubtful = doubtful || (g.id != d.id && !accounted[g.id] && in_gate(g, d.centroid_px));
    }
    if (doubtful) {
      ++report_.dropped_by_prediction;
      continue;
    }
    kept.push_back(d);
  }
  // Detections on a kept tracked dot are taken. The others are named by gated nearest prediction, every
  // gate competing and every detection counted (one on a tracked dot in another's gate makes that gate
  // ambiguous), but only a gate short enough names. A dot with no such gate gets a candidate
  // (dot_prediction.h): the one detection in its long gate that nobody tracked and no naming gate holds,
  // which the next settled pose confirms or forgets.
  std::vector<bool> taken(detected.dots.size(), false), loose(detected.dots.size(), true);
  for (size_t k = 0; k < detected.dots.size(); ++k) {
    for (const tracking::PreviousDot& d : kept) {
      taken[k] = taken[k] || (d.centroid_px - centroids[k]).norm() < o_.detector.duplicate_distance_px;
    }
    for (const tracking::PredictedDot& g : naming) loose[k] = loose[k] && !taken[k] && !in_gate(g, centroids[k]);
  }
  std::map<int, bool> known;
  for (const tracking::PreviousDot& d : kept) known[d.id] = true;
  const tracking::PredictedMatch match = tracking::MatchPredictions(gates, centroids, o_.predicted_match);
  report_.ambiguous_by_prediction += match.ambiguous;
  for (size_t k = 0; k < detected.dots.size(); ++k) {
    const int id = match.id_of_detection[k];
    if (taken[k] || id < 0 || known[id]) continue;  // a known id: its tracked blob is elsewhere in the gate
    kept.push_back(tracking::MakePreviousDot(id, detected.dots[k]));
    known[id] = true;
    ++report_.named_by_prediction;
  }
  for (size_t j = 0; j < gates.size(); ++j) {
    const tracking::PredictedDot& g = gates[j];
    if (known[g.id] || g.names || gate_sigma[j] > o_.prediction.max_candidate_gate_sigma_px) continue;
    int inside = 0;
    size_t which = 0;
    for (size_t k = 0; k < detected.dots.size(); ++k) {
      if (loose[k] && in_gate(g, centroids[k])) {
        ++inside;
        which = k;
      }
    }
    if (inside == 1) {
      candidates_.push_back(tracking::MakePreviousDot(g.id, detected.dots[which]));
      known[g.id] = true;  // one candidate per dot
    }
  }
  tracked_ = std::move(kept);
}

namespace {

struct EndOfSessionNaming {
  std::map<size_t, std::vector<tracking::PreviousDot>> named;  // by sample index, in the order named
  std::vector<std::string> log;
};

// Every name the end of the session gives (late_naming.h, then seen_once.h, then late naming again), in
// memory: a pure function of the samples and their frames' detections.
EndOfSessionNaming NameAtTheEnd(PredictionModel model, std::vector<ViewedSample> all,
                                const std::vector<tracking::DetectionReport>& detected, const RunOptions& o) {
  EndOfSessionNaming out;
  LateNamingOptions options;
  options.prediction = o.prediction;
  options.correction = o.prediction_correction;
  options.match = o.predicted_match;
  options.duplicate_distance_px = o.detector.duplicate_distance_px;
  options.min_other_samples = o.late_min_other_samples;
  // The samples' cameras and f_x as their images give them (bundled_cameras.h).
  const BundledCameras bundled = BundleSampleCameras(model, all, o.prediction);
  out.log.push_back("cameras of the samples from their images: " + bundled.message);
  UseBundledCameras(bundled, &model, &all);
  int named = 0;
  auto add = [&](size_t k, const std::vector<tracking::PreviousDot>& dots) {
    for (const tracking::PreviousDot& d : dots) {
      all[k].dots_px[d.id] = d.centroid_px;
      out.named[k].push_back(d);
    }
    named += static_cast<int>(dots.size());
  };
  // Passes over the samples, each naming from all the others, until one names nothing.
  auto late_passes = [&] {
    for (int pass = 0; pass < o.late_naming_passes; ++pass) {
      const int before = named;
      for (size_t k = 0; k < all.size(); ++k) {
        std::vector<ViewedSample> others;
        for (size_t j = 0; j < all.size(); ++j) {
          if (j != k) others.push_back(all[j]);
        }
        add(k, acquisition::NameLater(model, others, all[k], detected[k], options).named);
      }
      if (named == before) break;  // nothing new: another pass would name nothing
    }
  };
  late_passes();
  // Then the dots held by few samples, by hypotheses that further samples support.
  SeenOnceOptions seen_once;
  seen_once.prediction = o.prediction;
  seen_once.duplicate_distance_px = o.detector.duplicate_distance_px;
  const SeenOnceReport few = NameSeenOnce(model, all, detected, seen_once);
  std::map<size_t, std::vector<tracking::PreviousDot>> by_sample;
  for (const SeenOnceName& n : few.named) by_sample[static_cast<size_t>(n.sample)].push_back(n.dot);
  for (const auto& [k, dots] : by_sample) add(k, dots);
  out.log.push_back("dots held by few samples: " + std::to_string(few.looked_for) + " looked for, " +
                    std::to_string(few.dots_named) + " named in " + std::to_string(few.named.size()) +
                    " further frames, " + std::to_string(few.rivalled) + " with rival hypotheses, " +
                    std::to_string(few.conflicts) + " in conflict");
  // Their new rays fix points of other dots better, which the samples lacking them may now name.
  if (few.dots_named > 0) late_passes();
  return out;
}

}  // namespace

bool Runner::NameLater() {
  if (c_.prediction == nullptr || c_.session == nullptr || o_.late_naming_passes <= 0) return true;
  Result<session::SessionLog> log = session::ReadSessionLog(c_.session->journal().records());
  if (!log.ok()) return true;  // the loop read it before: nothing is named rather than a doubtful name
  AcceptedSamples();           // viewed_, by pose, with every sample of the journal

  // Each accepted sample's frame, read again and detected once (an unreadable one names nothing).
  std::vector<int> poses;
  std::vector<tracking::DetectionReport> detected;
  for (const auto& [pose, s] : *viewed_) {
    const std::optional<session::AcceptedSample>& a = log->accepted.at(static_cast<size_t>(pose));
    Result<std::string> bytes = ReadFileCapped(c_.session->path() + "/" + a->image, 64 << 20);
    Result<vpImage<unsigned char>> image =
        bytes.ok() ? capture::DecodeGreyPng(*bytes, a->image) : Result<vpImage<unsigned char>>(bytes.status());
    poses.push_back(pose);
    detected.emplace_back();
    if (!image.ok()) {
      ++report_.faults["late_naming_unreadable_image"];
      Log("pose " + a->id + ": its image could not be read again (" + image.status().message() + ")");
      continue;
    }
    detected.back() = tracking::DetectDots(*image, o_.detector);
  }
  // The state this step starts from: every sample without the dots an earlier, interrupted run of it
  // named, so that a run resumed after a kill in the middle of it names exactly what an uninterrupted
  // one does; only what is not in the journal yet is written.
  std::vector<ViewedSample> all;
  for (const int pose : poses) {
    ViewedSample s = (*viewed_)[pose];
    const session::AcceptedSample& a = *log->accepted.at(static_cast<size_t>(pose));
    for (size_t k = a.dots.size() - static_cast<size_t>(a.named_later); k < a.dots.size(); ++k) s.dots_px.erase(a.dots[k].id);
    all.push_back(s);
  }
  EndOfSessionNaming end = NameAtTheEnd(*c_.prediction, std::move(all), detected, o_);
  for (const std::string& line : end.log) Log(line);
  std::set<int> gained;  // poses whose samples gained dots
  for (const auto& [k, dots] : end.named) {
    const int pose = poses[k];
    std::vector<tracking::PreviousDot> fresh;
    for (const tracking::PreviousDot& d : dots) {
      if (!(*viewed_)[pose].dots_px.count(d.id)) fresh.push_back(d);
    }
    if (fresh.empty()) continue;
    if (!Record({{"type", "dots_named_later"}, {"pose", pose}, {"dots", DotsJson(fresh)}})) return false;
    for (const tracking::PreviousDot& d : fresh) (*viewed_)[pose].dots_px[d.id] = d.centroid_px;
    report_.named_later += static_cast<int>(fresh.size());
    gained.insert(pose);
    Log("pose " + plan_[static_cast<size_t>(pose)].id + ": " + std::to_string(fresh.size()) + " dots named later");
  }
  report_.samples_named_later = static_cast<int>(gained.size());
  return true;
}

}  // namespace selfcal::acquisition::internal
