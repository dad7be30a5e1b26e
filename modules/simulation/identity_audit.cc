#include "simulation/identity_audit.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "kinematics/robot_model.h"
#include "sim/image_renderer.h"

namespace selfcal::simulation {

namespace {

// Geometry only: the flags and centres of RenderDots do not depend on the sampling or the grey levels.
sim::RenderOptions GeometryOnly() {
  sim::RenderOptions o;
  o.supersampling = 1;
  return o;
}

// Scores one sample's names against the rendered truth of its view; appends its wrong names.
nlohmann::json MissedJson(const std::vector<std::pair<int, Eigen::Vector2d>>& missed) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [id, uv] : missed) out.push_back({{"id", id}, {"u", uv.x()}, {"v", uv.y()}});
  return out;
}

SampleIdentities AuditSample(const session::AcceptedSample& sample, const sim::RenderedImage& truth, double gate_px,
                             std::vector<WrongIdentity>* wrong) {
  SampleIdentities s;
  s.pose = sample.pose;
  s.pose_id = sample.id;
  for (const sim::RenderedDot& d : truth.dots) s.in_view += d.in_front && d.fully_inside ? 1 : 0;
  std::vector<bool> named_id(truth.dots.size(), false);
  for (const session::SampleDot& named : sample.dots) {
    if (named.id >= 0 && named.id < static_cast<int>(truth.dots.size())) named_id[named.id] = true;
  }
  for (const sim::RenderedDot& d : truth.dots) {
    if (d.in_front && d.fully_inside && !named_id[d.id]) s.missed.push_back({d.id, d.projected_centre_px});
  }
  for (const session::SampleDot& named : sample.dots) {
    ++s.named;
    const Eigen::Vector2d pixel(named.u_px, named.v_px);
    WrongIdentity w;
    w.pose = sample.pose;
    w.pose_id = sample.id;
    w.id = named.id;
    w.pixel_px = pixel;
    const bool known = named.id >= 0 && named.id < static_cast<int>(truth.dots.size());
    if (known) {
      const sim::RenderedDot& own = truth.dots[named.id];
      if (own.in_front) w.own_distance_px = (pixel - own.projected_centre_px).norm();
      s.named_in_view += own.in_front && own.fully_inside ? 1 : 0;
    }
    for (const sim::RenderedDot& d : truth.dots) {
      if (!d.in_front) continue;
      const double distance = (pixel - d.projected_centre_px).norm();
      if (distance < w.true_distance_px) {
        w.true_distance_px = distance;
        w.true_id = d.id;
      }
    }
    if (w.own_distance_px <= gate_px && w.true_id == named.id) {
      s.max_right_error_px = std::max(s.max_right_error_px, w.own_distance_px);
    } else {
      ++s.wrong;
      wrong->push_back(w);
    }
  }
  return s;
}

}  // namespace

IdentityAudit AuditIdentities(const sim::SimResult& world, const session::SessionLog& log,
                              const IdentityAuditOptions& options) {
  IdentityAudit audit;
  audit.gate_px = options.gate_px;
  audit.configuration = world.truth.nominal.mount;
  audit.poses_planned = log.num_poses;
  const sim::SimTruth& truth = world.truth;
  const sim::DotScene scene = sim::MakeDotScene(truth);
  for (const std::optional<session::AcceptedSample>& sample : log.accepted) {
    if (!sample) continue;
    const Eigen::VectorXd joints = Eigen::Map<const Eigen::VectorXd>(sample->joints_rad.data(),
                                                                     static_cast<Eigen::Index>(sample->joints_rad.size()));
    const Rigid3 base_from_cam = PointsFromCam(truth.nominal, truth.rho_true, joints);  // the points' frame
    const sim::RenderedImage view = sim::RenderDots(truth.camera_true, base_from_cam, scene, GeometryOnly(), 0);
    audit.samples.push_back(AuditSample(*sample, view, options.gate_px, &audit.wrong));
  }
  audit.samples_accepted = static_cast<int>(audit.samples.size());
  if (audit.samples.empty()) return audit;
  audit.named_min = audit.samples.front().named;
  audit.in_view_min = audit.samples.front().in_view;
  audit.ratio_min = audit.samples.front().ratio();
  for (const SampleIdentities& s : audit.samples) {
    audit.named_mean += s.named;
    audit.in_view_mean += s.in_view;
    audit.ratio_mean += s.ratio();
    audit.named_min = std::min(audit.named_min, s.named);
    audit.in_view_min = std::min(audit.in_view_min, s.in_view);
    audit.ratio_min = std::min(audit.ratio_min, s.ratio());
    audit.wrong_total += s.wrong;
    audit.max_right_error_px = std::max(audit.max_right_error_px, s.max_right_error_px);
  }
  const double n = static_cast<double>(audit.samples.size());
  audit.named_mean /= n;
  audit.in_view_mean /= n;
  audit.ratio_mean /= n;
  for (const WrongIdentity& w : audit.wrong) {
    if (!audit.worst || w.own_distance_px > audit.worst->own_distance_px) audit.worst = w;
  }
  return audit;
}

namespace {

nlohmann::json Distance(double px) { return std::isfinite(px) ? nlohmann::json(px) : nlohmann::json(); }

nlohmann::json WrongJson(const WrongIdentity& w) {
  return {{"pose", w.pose},
          {"pose_id", w.pose_id},
          {"id", w.id},
          {"u_px", w.pixel_px.x()},
          {"v_px", w.pixel_px.y()},
          {"own_distance_px", Distance(w.own_distance_px)},
          {"true_id", w.true_id},
          {"true_distance_px", Distance(w.true_distance_px)}};
}

}  // namespace

nlohmann::json IdentityAuditJson(const IdentityAudit& audit) {
  nlohmann::json samples = nlohmann::json::array();
  for (const SampleIdentities& s : audit.samples) {
    samples.push_back({{"pose", s.pose},
                       {"pose_id", s.pose_id},
                       {"in_view", s.in_view},
                       {"named", s.named},
                       {"named_in_view", s.named_in_view},
                       {"wrong", s.wrong},
                       {"max_right_error_px", s.max_right_error_px},
                       {"missed", MissedJson(s.missed)}});
  }
  nlohmann::json wrong = nlohmann::json::array();
  for (size_t k = 0; k < audit.wrong.size() && k < 50; ++k) wrong.push_back(WrongJson(audit.wrong[k]));
  return {{"configuration", CameraMountName(audit.configuration)},
          {"gate_px", audit.gate_px},
          {"poses_planned", audit.poses_planned},
          {"samples_accepted", audit.samples_accepted},
          {"named_per_sample", {{"mean", audit.named_mean}, {"min", audit.named_min}}},
          {"in_view_per_sample", {{"mean", audit.in_view_mean}, {"min", audit.in_view_min}}},
          {"named_of_in_view", {{"mean", audit.ratio_mean}, {"min", audit.ratio_min}}},
          {"wrong_total", audit.wrong_total},
          {"max_right_error_px", audit.max_right_error_px},
          {"worst_wrong", audit.worst ? WrongJson(*audit.worst) : nlohmann::json()},
          {"wrong", wrong},
          {"samples", samples}};
}

std::string IdentityAuditSummary(const IdentityAudit& audit) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << CameraMountName(audit.configuration) << ": " << audit.samples_accepted << "/" << audit.poses_planned
      << " samples accepted; named per sample mean "
      << audit.named_mean << ", min " << audit.named_min << " of in view mean " << audit.in_view_mean << " (ratio mean "
      << 100 * audit.ratio_mean << " %, min " << 100 * audit.ratio_min << " %); " << audit.wrong_total
      << " wrong identities (gate " << audit.gate_px << " px; right names within ";
  out.precision(3);
  out << audit.max_right_error_px << " px)";
  return out.str();
}

}  // namespace selfcal::simulation
