#include "twoview/planar_views.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview {

namespace {

// One view's dots shared with the reference (index-aligned) and the inliers of its homography.
struct ViewData {
  std::vector<Eigen::Vector2d> ref_px, view_px;
  std::vector<int> inliers;
};

struct Candidate {
  Rigid3 cam_from_ref;  // translation in reference plane distances
  Eigen::Vector3d normal;
};

void Normalise(const CameraIntrinsics& camera, double fx, const std::vector<Eigen::Vector2d>& px,
               std::vector<Eigen::Vector2d>* out) {
  out->resize(px.size());
  for (size_t k = 0; k < px.size(); ++k) (*out)[k] = PixelToNormalized(camera, fx, px[k]);
}

Eigen::Vector3d MeanBearing(const std::vector<Eigen::Vector2d>& n, const std::vector<int>& indices) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i : indices) sum += Eigen::Vector3d(n[i].x(), n[i].y(), 1).normalized();
  return sum.normalized();
}

// Homography of the listed points in normalised coordinates at focal fx (x_view ~ H x_ref).
bool NormalisedHomography(const CameraIntrinsics& camera, double fx, const ViewData& v, const std::vector<int>& indices,
                          std::vector<Eigen::Vector2d>* n_ref, std::vector<Eigen::Vector2d>* n_view, Eigen::Matrix3d* h) {
  Normalise(camera, fx, v.ref_px, n_ref);
  Normalise(camera, fx, v.view_px, n_view);
  return internal::HomographyDlt(*n_ref, *n_view, indices, h);
}

// Transfer errors in image j (px at focal fx) of every shared dot.
std::vector<double> TransferPx(const Eigen::Matrix3d& h, const std::vector<Eigen::Vector2d>& n_ref,
                               const std::vector<Eigen::Vector2d>& n_view, double fx) {
  std::vector<double> errors;
  const Eigen::Matrix3d h_inv = h.inverse();
  for (size_t k = 0; k < n_ref.size(); ++k) {
    double e12 = 0, e21 = 0;
    internal::TransferErrors(h, h_inv, n_ref[k], n_view[k], &e12, &e21);
    errors.push_back(std::sqrt(e12) * fx);
  }
  return errors;
}

// The physical decompositions of a normalised homography: scaled to a unit middle singular value with a
// positive determinant (both cameras on the same side of the plane), H - R of rank one (= t n^T), the
// points in front of the reference camera (n . b > 0) and of view j ((R n) . b > 0). Typically two.
std::vector<Candidate> PhysicalCandidates(const Eigen::Matrix3d& h, const Eigen::Vector3d& ref_bearing,
                                          const Eigen::Vector3d& view_bearing) {
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(h).singularValues();
  if (!(sv(1) > 0)) return {};
  Eigen::Matrix3d hs = h / sv(1);
  if (hs.determinant() < 0) hs = -hs;
  std::vector<Candidate> out;
  for (const Rigid3& pose : internal::DecomposeHomography(hs)) {
    Eigen::Vector3d n, t;
    if (!internal::PlaneOfDecomposition(hs, pose.rotation, ref_bearing, &n, &t)) continue;
    if ((pose.rotation * n).dot(view_bearing) <= 0 || 1 + n.dot(pose.rotation.transpose() * t) <= 0) continue;
    const bool duplicate = std::any_of(out.begin(), out.end(), [&](const Candidate& c) {
      return (c.cam_from_ref.rotation - pose.rotation).norm() < 1e-9 && (c.normal - n).norm() < 1e-9;
    });
    if (!duplicate) out.push_back({Rigid3(pose.rotation, t), n});
  }
  return out;
}

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Consensus {
  double cost = std::numeric_limits<double>::infinity();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  std::vector<int> chosen;  // per view, index into its candidates (-1: none)
};

// The normal most views agree with: every candidate normal is tried as the seed, each view votes with
// its nearest candidate (squared angle, capped so that one bad view cannot dominate), and the best
// seed's votes are averaged.
Consensus FindConsensus(const std::vector<std::vector<Candidate>>& candidates) {
  const double cap = std::pow(15.0 * kPi / 180.0, 2);
  auto score = [&](const Eigen::Vector3d& seed, std::vector<int>* chosen) {
    double cost = 0;
    chosen->assign(candidates.size(), -1);
    for (size_t v = 0; v < candidates.size(); ++v) {
      double best = cap;
      for (size_t c = 0; c < candidates[v].size(); ++c) {
        const double a2 = std::pow(Angle(candidates[v][c].normal, seed), 2);
        if (a2 < best) {
          best = a2;
          (*chosen)[v] = static_cast<int>(c);
        }
      }
      if (!candidates[v].empty()) cost += best;
    }
    return cost;
  };
  Consensus result;
  std::vector<int> chosen;
  for (const auto& view : candidates) {
    for (const Candidate& seed : view) {
      const double cost = score(seed.normal, &chosen);
      if (cost < result.cost) {
        result.cost = cost;
        result.chosen = chosen;
        result.normal = seed.normal;
      }
    }
  }
  if (result.chosen.empty()) return result;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t v = 0; v < candidates.size(); ++v) {
    if (result.chosen[v] >= 0) sum += candidates[v][result.chosen[v]].normal;
  }
  if (sum.norm() > 0) {
    result.normal = sum.normalized();
    result.cost = score(result.normal, &result.chosen);
  }
  return result;
}

// Every view's candidates at focal fx (empty for the reference and for views that failed).
std::vector<std::vector<Candidate>> CandidatesAt(const CameraIntrinsics& camera, double fx,
                                                 const std::vector<ViewData>& data) {
  std::vector<std::vector<Candidate>> out(data.size());
  std::vector<Eigen::Vector2d> n_ref, n_view;
  for (size_t v = 0; v < data.size(); ++v) {
    if (data[v].inliers.empty()) continue;
    Eigen::Matrix3d h;
    if (!NormalisedHomography(camera, fx, data[v], data[v].inliers, &n_ref, &n_view, &h)) continue;
    out[v] = PhysicalCandidates(h, MeanBearing(n_ref, data[v].inliers), MeanBearing(n_view, data[v].inliers));
  }
  return out;
}

double CostAt(const CameraIntrinsics& camera, double fx, const std::vector<ViewData>& data) {
  return FindConsensus(CandidatesAt(camera, fx, data)).cost;
}

// f_x minimising the normals' disagreement: a log-spaced grid, then golden-section search in the
// bracket of the grid's best point. *interior false when the best point is on the search range's edge.
double SearchFocal(const CameraIntrinsics& camera, const std::vector<ViewData>& data, const PlanarViewsOptions& options,
                   bool* interior) {
  const double lo = std::log(camera.fx_px * options.min_focal_ratio);
  const double hi = std::log(camera.fx_px * options.max_focal_ratio);
  const int steps = std::max(options.focal_steps, 3);
  std::vector<double> costs(steps);
  int best = 0;
  for (int k = 0; k < steps; ++k) {
    costs[k] = CostAt(camera, std::exp(lo + (hi - lo) * k / (steps - 1)), data);
    if (costs[k] < costs[best]) best = k;
  }
  *interior = best > 0 && best < steps - 1;
  double a = lo + (hi - lo) * std::max(best - 1, 0) / (steps - 1);
  double b = lo + (hi - lo) * std::min(best + 1, steps - 1) / (steps - 1);
  const double golden = (std::sqrt(5.0) - 1) / 2;
  double c = b - golden * (b - a), d = a + golden * (b - a);
  double fc = CostAt(camera, std::exp(c), data), fd = CostAt(camera, std::exp(d), data);
  for (int it = 0; it < 40; ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - golden * (b - a);
      fc = CostAt(camera, std::exp(c), data);
    } else {
      a = c, c = d, fc = fd;
      d = a + golden * (b - a);
      fd = CostAt(camera, std::exp(d), data);
    }
  }
  return std::exp((a + b) / 2);
}

// Shared dots of each view with the reference, and the inliers of its homography at the prior focal.
std::vector<ViewData> PrepareViews(const CameraIntrinsics& camera, const std::vector<std::map<int, Eigen::Vector2d>>& views,
                                   int reference, const PlanarViewsOptions& options, PlanarViewsReport* report) {
  std::vector<ViewData> data(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    PlanarView& out = report->views[v];
    if (static_cast<int>(v) == reference) continue;
    for (const auto& [id, px] : views[v]) {
      auto it = views[reference].find(id);
      if (it == views[reference].end()) continue;
      data[v].ref_px.push_back(it->second);
      data[v].view_px.push_back(px);
    }
    out.num_points = static_cast<int>(data[v].ref_px.size());
    if (out.num_points < options.min_points) {
      out.message = std::to_string(out.num_points) + " dots shared with the reference (need " +
                    std::to_string(options.min_points) + ")";
      continue;
    }
    std::vector<int> all(out.num_points);
    for (int k = 0; k < out.num_points; ++k) all[k] = k;
    std::vector<Eigen::Vector2d> n_ref, n_view;
    Eigen::Matrix3d h;
    if (!NormalisedHomography(camera, camera.fx_px, data[v], all, &n_ref, &n_view, &h)) {
      out.message = "no homography (degenerate dots)";
      continue;
    }
    const std::vector<double> errors = TransferPx(h, n_ref, n_view, camera.fx_px);
    for (int k = 0; k < out.num_points; ++k) {
      if (errors[k] <= options.outlier_px) data[v].inliers.push_back(k);
    }
    if (static_cast<int>(data[v].inliers.size()) < options.min_points) {
      out.message = "the dots do not lie on one plane (fewer than " + std::to_string(options.min_points) +
                    " within " + std::to_string(options.outlier_px) + " px of a homography)";
      data[v].inliers.clear();
    }
  }
  return data;
}

}  // namespace

PlanarViewsReport SolvePlanarViews(const CameraIntrinsics& camera, const std::vector<std::map<int, Eigen::Vector2d>>& views,
                                   int reference, const PlanarViewsOptions& options) {
  PlanarViewsReport report;
  report.reference = reference;
  report.fx_px = camera.fx_px;
  report.views.resize(views.size());
  if (reference < 0 || reference >= static_cast<int>(views.size())) {
    report.message = "no reference view";
    return report;
  }
  report.views[reference].ok = true;
  report.views[reference].resolved = true;
  report.views[reference].message = "reference";
  const std::vector<ViewData> data = PrepareViews(camera, views, reference, options, &report);
  const int usable = static_cast<int>(std::count_if(data.begin(), data.end(), [](const ViewData& d) { return !d.inliers.empty(); }));
  if (usable < 1) {
    report.message = "no view shares enough dots on one plane with the reference";
    return report;
  }
  bool interior = false;
  if (options.estimate_focal && usable >= 2) {
    const double fx = SearchFocal(camera, data, options, &interior);
    if (interior) {
      report.fx_px = fx;
      report.fx_estimated = true;
    }
  }
  const std::vector<std::vector<Candidate>> candidates = CandidatesAt(camera, report.fx_px, data);
  const Consensus consensus = FindConsensus(candidates);
  report.normal_in_ref = consensus.normal;
  std::vector<Eigen::Vector2d> n_ref, n_view;
  std::vector<double> spreads, transfers;
  for (size_t v = 0; v < views.size(); ++v) {
    PlanarView& out = report.views[v];
    if (static_cast<int>(v) == reference || data[v].inliers.empty()) continue;
    if (candidates[v].empty() || consensus.chosen.empty() || consensus.chosen[v] < 0) {
      out.message = candidates[v].empty() ? "the homography has no physical decomposition"
                                          : "no solution within 15 deg of the other views' plane";
      continue;
    }
    Eigen::Matrix3d h;
    NormalisedHomography(camera, report.fx_px, data[v], data[v].inliers, &n_ref, &n_view, &h);
    const std::vector<double> errors = TransferPx(h, n_ref, n_view, report.fx_px);
    double sum2 = 0;
    for (int k : data[v].inliers) sum2 += errors[k] * errors[k];
    out.num_inliers = static_cast<int>(data[v].inliers.size());
    out.transfer_rms_px = std::sqrt(sum2 / out.num_inliers);
    transfers.push_back(out.transfer_rms_px);
    const Candidate& chosen = candidates[v][consensus.chosen[v]];
    out.ok = true;
    out.cam_from_ref = chosen.cam_from_ref;
    out.normal_in_ref = chosen.normal;
    out.normal_error_rad = Angle(chosen.normal, consensus.normal);
    spreads.push_back(out.normal_error_rad);
    double rival_error = std::numeric_limits<double>::infinity();
    for (size_t c = 0; c < candidates[v].size(); ++c) {
      const double e = Angle(candidates[v][c].normal, consensus.normal);
      if (static_cast<int>(c) == consensus.chosen[v] || e >= rival_error) continue;
      rival_error = e;
      out.has_rival = true;
      out.rival_cam_from_ref = candidates[v][c].cam_from_ref;
      out.rival_normal_in_ref = candidates[v][c].normal;
      out.rival_normal_error_rad = e;
    }
    out.resolved = !out.has_rival || out.rival_normal_error_rad - out.normal_error_rad >=
                                         options.resolve_margin_deg * kPi / 180.0;
    out.message = out.resolved ? "resolved by the plane" : "ambiguous: both solutions agree with the plane";
    ++report.views_ok;
    report.views_resolved += out.resolved ? 1 : 0;
  }
  double sum2 = 0;
  for (double s : spreads) sum2 += s * s;
  report.normal_rms_rad = spreads.empty() ? 0 : std::sqrt(sum2 / spreads.size());
  if (!transfers.empty()) {
    std::nth_element(transfers.begin(), transfers.begin() + transfers.size() / 2, transfers.end());
    report.median_transfer_rms_px = transfers[transfers.size() / 2];
  }
  report.ok = report.views_ok >= 1 && report.normal_rms_rad <= options.max_normal_rms_deg * kPi / 180.0;
  std::ostringstream msg;
  msg << report.views_ok << " of " << views.size() - 1 << " views on the plane, " << report.views_resolved
      << " resolved, normal spread " << report.normal_rms_rad * 180 / kPi << " deg RMS, f_x " << report.fx_px << " px "
      << (report.fx_estimated ? "from the plane" : "(prior)") << ", homography transfer " << report.median_transfer_rms_px
      << " px median";
  if (!report.ok && report.views_ok >= 1) msg << ": the views do not agree on one plane";
  report.message = msg.str();
  return report;
}

}  // namespace selfcal::twoview
