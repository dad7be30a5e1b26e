#include "acquisition/seen_once.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "acquisition/late_naming.h"

namespace selfcal::acquisition {
namespace {

using Detection = std::pair<int, int>;  // (sample, detection index)

struct Observation {
  int sample = -1;
  Eigen::Vector2d uv_px;
};

struct Hypothesis {
  std::vector<Detection> detections;  // the seed first, then the supports
  Point x;
};

struct Search {
  const PredictionModel& model;
  const std::vector<ViewedSample>& samples;
  const std::vector<tracking::DetectionReport>& detected;
  const SeenOnceOptions& o;
  std::vector<Rigid3> base_from_cams, cam_from_bases;
  std::vector<std::vector<int>> free;  // per sample: the detections no held dot accounts for

  Eigen::Vector2d Pixel(const Detection& d) const {
    return detected[static_cast<size_t>(d.first)].dots[static_cast<size_t>(d.second)].centroid_px;
  }

  // The point on every observation's ray, when it reprojects within the residual bound onto each.
  bool Fit(const std::vector<Observation>& obs, Point* x) const {
    std::vector<Ray> rays;
    for (const Observation& b : obs) rays.push_back(RayOf(model, base_from_cams[static_cast<size_t>(b.sample)], b.uv_px));
    if (rays.size() < 2 || !Triangulate(model, o.prediction.ray_model_sigma_px, rays, x)) return false;
    for (const Observation& b : obs) {
      const std::optional<Eigen::Vector2d> uv = Project(model.camera, cam_from_bases[static_cast<size_t>(b.sample)] * x->p);
      if (!uv || (*uv - b.uv_px).norm() > o.ray_residual_px) return false;
    }
    return true;
  }

  // The hypothesis grown from `seed` on the dot's observations `held`: empty when it does not fit,
  // gathers too few supports, or too many further samples hold a named dot in its short gate.
  std::optional<Hypothesis> Grow(const std::vector<Observation>& held, const std::set<int>& holders,
                                 const Detection& seed) const {
    Hypothesis h;
    h.detections = {seed};
    int contradicted = 0;  // further samples with a named dot in the hypothesis's short gate
    for (int round = 0; round < o.grow_rounds; ++round) {
      contradicted = 0;
      std::vector<Observation> obs = held;
      for (const Detection& d : h.detections) obs.push_back({d.first, Pixel(d)});
      if (!Fit(obs, &h.x)) return std::nullopt;
      std::vector<Detection> next = {seed};
      for (size_t j = 0; j < samples.size(); ++j) {
        const int s = static_cast<int>(j);
        if (s == seed.first || holders.count(s)) continue;
        tracking::PredictedDot gate;
        if (!ProjectPrediction(model, cam_from_bases[j], h.x, -1, &gate) ||
            !InImage(model.camera, gate.uv_px, o.in_view_margin_px) || GateSigmaPx(gate) > o.max_support_sigma_px) {
          continue;
        }
        const bool named_there = std::any_of(samples[j].dots_px.begin(), samples[j].dots_px.end(),
                                             [&](const auto& d) { return tracking::Mahalanobis2(gate, d.second) <= o.gate_chi2; });
        if (named_there) {
          ++contradicted;
          continue;
        }
        std::vector<int> inside;
        for (const int k : free[j]) {
          if (tracking::Mahalanobis2(gate, Pixel({s, k})) <= o.gate_chi2) inside.push_back(k);
        }
        if (inside.size() == 1) next.push_back({s, inside.front()});
      }
      const bool settled = next == h.detections;
      h.detections = std::move(next);
      if (settled) break;
    }
    std::vector<Observation> obs = held;
    for (const Detection& d : h.detections) obs.push_back({d.first, Pixel(d)});
    const int support = static_cast<int>(h.detections.size()) - 1;
    if (!Fit(obs, &h.x) || support < o.min_support || contradicted * o.max_contradicted_per_support > support) {
      return std::nullopt;
    }
    return h;
  }

  // The best supported hypothesis of dot `id`, or none (`*rivalled`: another that shares none of its
  // detections has at least half its support: a neighbour near the dot's rays, seen where the dot is not).
  std::optional<Hypothesis> Best(int id, bool* rivalled) const {
    std::vector<Observation> held;
    std::set<int> holders;
    for (size_t s = 0; s < samples.size(); ++s) {
      if (const auto it = samples[s].dots_px.find(id); it != samples[s].dots_px.end()) {
        held.push_back({static_cast<int>(s), it->second});
        holders.insert(static_cast<int>(s));
      }
    }
    std::vector<Hypothesis> found;
    std::set<Detection> covered;  // detections of a hypothesis found: not tried again as seeds
    for (size_t k = 0; k < samples.size(); ++k) {
      if (holders.count(static_cast<int>(k))) continue;
      for (const int c : free[k]) {
        const Detection seed{static_cast<int>(k), c};
        if (covered.count(seed)) continue;
        std::optional<Hypothesis> h = Grow(held, holders, seed);
        if (!h) continue;
        covered.insert(h->detections.begin(), h->detections.end());
        found.push_back(std::move(*h));
      }
    }
    if (found.empty()) return std::nullopt;
    const auto best = std::max_element(found.begin(), found.end(), [](const Hypothesis& a, const Hypothesis& b) {
      return a.detections.size() < b.detections.size();
    });
    const std::set<Detection> mine(best->detections.begin(), best->detections.end());
    for (const Hypothesis& h : found) {
      const bool shares = std::any_of(h.detections.begin(), h.detections.end(),
                                      [&](const Detection& d) { return mine.count(d) > 0; });
      if (!shares && 2 * h.detections.size() >= best->detections.size()) {
        *rivalled = true;
        return std::nullopt;
      }
    }
    return *best;
  }
};

}  // namespace

SeenOnceReport NameSeenOnce(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                            const std::vector<tracking::DetectionReport>& detected, const SeenOnceOptions& options) {
  SeenOnceReport report;
  if (samples.size() < 3 || detected.size() != samples.size()) return report;
  Search search{model, samples, detected, options, SampleCameras(model, samples, options.prediction), {}, {}};
  for (const Rigid3& b : search.base_from_cams) search.cam_from_bases.push_back(b.Inverse());
  std::map<int, int> holders;  // dot id -> samples holding it
  for (size_t s = 0; s < samples.size(); ++s) {
    search.free.emplace_back();
    for (size_t k = 0; k < detected[s].dots.size(); ++k) {
      const Eigen::Vector2d& uv = detected[s].dots[k].centroid_px;
      const bool held = std::any_of(samples[s].dots_px.begin(), samples[s].dots_px.end(), [&](const auto& d) {
        return (d.second - uv).norm() < options.duplicate_distance_px;
      });
      if (!held) search.free.back().push_back(static_cast<int>(k));
    }
    for (const auto& [id, px] : samples[s].dots_px) ++holders[id];
  }
  std::map<int, Hypothesis> chosen;        // dot id -> its hypothesis
  std::map<Detection, std::set<int>> claims;  // detection -> the dots that would name it
  for (const auto& [id, n] : holders) {
    if (n > options.max_holders) continue;
    ++report.looked_for;
    bool rivalled = false;
    std::optional<Hypothesis> h = search.Best(id, &rivalled);
    report.rivalled += rivalled ? 1 : 0;
    if (!h) continue;
    for (const Detection& d : h->detections) claims[d].insert(id);
    chosen.emplace(id, std::move(*h));
  }
  std::set<int> conflicted;
  for (const auto& [d, ids] : claims) {
    if (ids.size() > 1) conflicted.insert(ids.begin(), ids.end());
  }
  report.conflicts = static_cast<int>(conflicted.size());
  std::vector<std::pair<Detection, int>> names;  // (detection, id), sorted by sample then detection
  for (const auto& [id, h] : chosen) {
    if (conflicted.count(id)) continue;
    ++report.dots_named;
    for (const Detection& d : h.detections) names.push_back({d, id});
  }
  std::sort(names.begin(), names.end());
  for (const auto& [d, id] : names) {
    const tracking::DotDetection& det = detected[static_cast<size_t>(d.first)].dots[static_cast<size_t>(d.second)];
    report.named.push_back({d.first, tracking::MakePreviousDot(id, det)});
  }
  return report;
}

}  // namespace selfcal::acquisition
