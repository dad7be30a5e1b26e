#include "kinematics/dh_table.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

namespace selfcal {
namespace {

// link_n_from_flange = Tx(a) Rx(alpha)? Then *a and *alpha.
bool IsTxRx(const Rigid3& t, double* a, double* alpha) {
  const Eigen::Matrix3d& r = t.rotation;
  constexpr double kTol = 1e-12;
  const bool ok = std::abs(r(0, 0) - 1) <= kTol && std::abs(r(0, 1)) <= kTol && std::abs(r(0, 2)) <= kTol &&
                  std::abs(r(1, 0)) <= kTol && std::abs(r(2, 0)) <= kTol && std::abs(t.translation.y()) <= kTol &&
                  std::abs(t.translation.z()) <= kTol;
  *a = t.translation.x();
  *alpha = std::atan2(r(2, 1), r(1, 1));
  return ok;
}

std::string Deg(double rad) {
  std::ostringstream out;
  out.precision(6);
  out << RadToDeg(rad);
  return out.str();
}

// The flange change when every beta is set to zero, worst over seeded random joints within the limits.
void DroppedBetaCost(const RobotModel& model, int samples, std::uint64_t seed, DhExpression* out) {
  RobotModel flat = model;
  for (LinkParameters& l : flat.links) l.beta = 0;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  const Eigen::VectorXd rho_flat = KinematicParameters::Nominal(flat);
  std::mt19937_64 rng(seed);
  Eigen::VectorXd q(model.num_joints());
  for (int s = 0; s < samples; ++s) {
    for (int j = 0; j < q.size(); ++j) {
      std::uniform_real_distribution<double> in(model.limits[j].min_rad, model.limits[j].max_rad);
      q[j] = in(rng);
    }
    const PoseDifference d = ComparePoses(BaseFromFlange(model, rho, q), BaseFromFlange(flat, rho_flat, q));
    out->dropped_position_m = std::max(out->dropped_position_m, d.position_m);
    out->dropped_rotation_rad = std::max(out->dropped_rotation_rad, d.rotation_rad);
  }
}

}  // namespace

DhExpression ExpressAsDh(const RobotModel& model, const std::string& convention_name, int samples,
                         std::uint64_t seed) {
  DhExpression out;
  DhTable& table = out.table;
  const int n = model.num_joints();
  table.limits = model.limits;
  table.flange_from_cam = model.flange_from_cam;
  table.hayati = convention_name == "modified_hayati";
  table.convention = convention_name == "standard" ? DhConvention::kStandard : DhConvention::kModified;
  if (!table.hayati) {
    for (int i = 0; i < n; ++i) {
      const double beta = model.links[i].beta;
      if (std::abs(beta) <= kNegligibleBetaRad) continue;
      out.losses.push_back("j" + std::to_string(i + 1) + ".beta = " + Deg(beta) + " deg: the tilt about y between axes " +
                           std::to_string(i) + " and " + std::to_string(i + 1) + " (Hayati's parallel-axis parameter), which " +
                           convention_name + " DH cannot hold");
    }
    if (!out.losses.empty()) DroppedBetaCost(model, samples, seed, &out);
  }
  if (table.convention == DhConvention::kStandard) {
    double a = 0, alpha = 0;
    if (!IsTxRx(model.link_n_from_flange, &a, &alpha)) {
      out.losses.push_back(
          "link_n_from_flange is not Tx(a) Rx(alpha): a standard DH table has no other transform from the last "
          "joint's frame to the flange");
    }
    if (!out.losses.empty()) return out;
    const LinkParameters& first = model.links[0];
    table.base_from_link0 = model.base_from_link0 * Rigid3(RotX(first.alpha), RotX(first.alpha) * Eigen::Vector3d(first.a, 0, 0));
    for (int i = 0; i < n; ++i) {
      const LinkParameters& l = model.links[i];
      const bool last = i + 1 == n;
      table.rows.push_back(DhRow{last ? a : model.links[i + 1].a, last ? alpha : model.links[i + 1].alpha, l.d, l.theta});
    }
    out.exact = true;
    return out;
  }
  if (!out.losses.empty()) return out;
  table.base_from_link0 = model.base_from_link0;
  table.link_n_from_flange = model.link_n_from_flange;
  for (const LinkParameters& l : model.links) {
    table.rows.push_back(DhRow{l.a, l.alpha, l.d, l.theta});
    table.betas.push_back(l.beta);
  }
  out.exact = true;
  return out;
}

RobotModel ModelOfDhTable(const std::string& name, const DhTable& table) {
  RobotModel model = RobotModel::FromDh(name, table.convention, table.rows, table.limits, table.base_from_link0,
                                        table.flange_from_cam);
  if (table.convention == DhConvention::kModified) {
    model.link_n_from_flange = table.link_n_from_flange;
    for (size_t i = 0; i < table.betas.size() && i < model.links.size(); ++i) model.links[i].beta = table.betas[i];
  }
  return model;
}

}  // namespace selfcal
