// Options validation, outcome names, and re-expressing a model's parameters on another model.
#include <cmath>
#include <set>
#include <sstream>

#include "base/status.h"
#include "bundle/bundle_adjustment.h"

#include <algorithm>

namespace selfcal::bundle {

std::string BundleOptions::Validate() const {
  std::ostringstream out;
  auto positive = [&](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0) out << name << " = " << v << " must be finite and > 0\n";
  };
  positive(huber_px, "huber_px");
  positive(screen_sigma, "screen_sigma");
  positive(yardstick_sigma_m, "yardstick_sigma_m");
  if (max_screen_rounds < 0) out << "max_screen_rounds = " << max_screen_rounds << " must be >= 0\n";
  if (max_iterations < 1) out << "max_iterations = " << max_iterations << " must be >= 1\n";
  if (!(function_tolerance >= 0)) out << "function_tolerance = " << function_tolerance << " must be >= 0\n";
  if (!(gradient_tolerance >= 0)) out << "gradient_tolerance = " << gradient_tolerance << " must be >= 0\n";
  if (!(parameter_tolerance >= 0)) out << "parameter_tolerance = " << parameter_tolerance << " must be >= 0\n";
  if (!(rank_tolerance > 0 && rank_tolerance < 1)) out << "rank_tolerance = " << rank_tolerance << " must lie in (0, 1)\n";
  if (!(weak_length_tolerance_m >= 0) || !std::isfinite(weak_length_tolerance_m)) {
    out << "weak_length_tolerance_m = " << weak_length_tolerance_m << " must be finite and >= 0\n";
  }
  if (!(weak_angle_tolerance_rad >= 0) || !std::isfinite(weak_angle_tolerance_rad)) {
    out << "weak_angle_tolerance_rad = " << weak_angle_tolerance_rad << " must be finite and >= 0\n";
  }
  if (min_identification_poses < 2) {
    out << "min_identification_poses = " << min_identification_poses << " must be >= 2\n";
  }
  return out.str();
}

namespace {

// An intrinsic by name (fy: the ratio mu = f_y / f_x, the one focal length selfcal keeps beside f_x) or
// one of the groups `lens` and `intrinsics`; false when `name` is none of them.
bool AddIntrinsics(const std::string& name, IntrinsicsMask* mask) {
  if (name == "intrinsics") {
    mask->fill(true);
    return true;
  }
  if (name == "lens") {
    for (int k : {kK1, kK2, kP1, kP2, kK3}) (*mask)[k] = true;
    return true;
  }
  const int index = name == "fy" ? static_cast<int>(kMu) : IntrinsicIndex(name);
  if (index < 0) return false;
  (*mask)[index] = true;
  return true;
}

}  // namespace

std::string ResolveParameterNames(const std::vector<std::string>& names, int num_joints, std::vector<int>* indices,
                                  IntrinsicsMask* intrinsics) {
  const KinematicParameters params(num_joints);
  std::set<int> chosen;
  std::ostringstream unknown;
  auto add_range = [&](int begin, int count) {
    for (int i = begin; i < begin + count; ++i) chosen.insert(i);
  };
  IntrinsicsMask named{};
  for (const std::string& name : names) {
    if (AddIntrinsics(name, &named)) {
      continue;
    } else if (name == "kinematics") {
      add_range(0, params.CamOffset());
    } else if (name == "base") {
      add_range(0, 6);
    } else if (name == "camera" || name == "hand_eye") {
      add_range(params.CamOffset(), 6);
    } else if (name.size() > 1 && name[0] == 'j' && name.find_first_not_of("0123456789", 1) == std::string::npos &&
               std::stoi(name.substr(1)) >= 1 && std::stoi(name.substr(1)) <= num_joints) {
      add_range(KinematicParameters::JointOffset(std::stoi(name.substr(1)) - 1), 5);
    } else if (const int index = params.IndexOf(name); index >= 0) {
      chosen.insert(index);
    } else {
      unknown << "unknown parameter `" << name << "`: give a parameter (e.g. j2.beta, cam.tx), a joint j1..j"
              << num_joints << ", base, camera (or hand_eye), kinematics, an intrinsic (fx, mu or fy, cx, cy, k1, k2, "
              << "p1, p2, k3), lens (k1, k2, p1, p2, k3) or intrinsics (all nine)\n";
    }
  }
  if (intrinsics != nullptr) {
    for (int k = 0; k < kNumIntrinsics; ++k) (*intrinsics)[k] = (*intrinsics)[k] || named[k];
  }
  indices->assign(chosen.begin(), chosen.end());
  return unknown.str();
}

IntrinsicsMask EstimatedIntrinsicsOf(const BundleOptions& options, int num_joints) {
  IntrinsicsMask held{}, free{};
  std::vector<int> ignored;
  ResolveParameterNames(options.held_parameters, num_joints, &ignored, &held);
  IntrinsicsMask out = options.intrinsics;
  if (!options.free_parameters.empty()) {
    ResolveParameterNames(options.free_parameters, num_joints, &ignored, &free);
    out = free;
  }
  for (int k = 0; k < kNumIntrinsics; ++k) out[k] = out[k] && !held[k];
  return out;
}

std::vector<int> HeldParameterIndices(const BundleOptions& options, int num_joints, std::string* unknown) {
  std::vector<int> held;
  std::string problems = ResolveParameterNames(options.held_parameters, num_joints, &held);
  if (!options.free_parameters.empty()) {
    std::vector<int> named_free;
    problems += ResolveParameterNames(options.free_parameters, num_joints, &named_free);
    const int n = KinematicParameters(num_joints).size();
    for (int i = 0; i < n; ++i) {
      if (std::find(named_free.begin(), named_free.end(), i) == named_free.end()) held.push_back(i);
    }
    std::sort(held.begin(), held.end());
    held.erase(std::unique(held.begin(), held.end()), held.end());
  }
  if (unknown != nullptr) *unknown = problems;
  return held;
}

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNotRun: return "not_run";
    case Outcome::kConverged: return "converged";
    case Outcome::kNoConvergence: return "unconverged";
    case Outcome::kFailure: return "failure";
    case Outcome::kInvalidInput: return "invalid_input";
    case Outcome::kScaleUnresolved: return "scale_unresolved";
    case Outcome::kDegenerate: return "degenerate";
  }
  return "unknown";
}

Eigen::VectorXd ExpressOnModel(const RobotModel& target, const RobotModel& source, const Eigen::VectorXd& source_rho) {
  SELFCAL_CHECK(target.num_joints() == source.num_joints(),
                "models with " << target.num_joints() << " and " << source.num_joints() << " joints");
  SELFCAL_CHECK(source_rho.size() == source.num_parameters(), "rho has " << source_rho.size() << " entries");
  const KinematicParameters params(target.num_joints());
  auto as_vector = [](const Rigid3& t, double* out) {
    const Eigen::Vector3d w = LogSO3(t.rotation);
    for (int k = 0; k < 3; ++k) {
      out[k] = t.translation[k];
      out[3 + k] = w[k];
    }
  };
  Eigen::VectorXd rho = source_rho;
  // base_from_link0_t Exp(b_t) = base_from_link0_s Exp(b_s).
  as_vector(target.base_from_link0.Inverse() * source.base_from_link0 * RigidFromTranslationRotvec(source_rho.data()),
            rho.data());
  const int cam = params.CamOffset();
  if (target.mount == CameraMount::kEyeToHand) {
    // base_from_cam_t Exp(c_t) = base_from_cam_s Exp(c_s); a change of link_n_from_flange moves the flange
    // frame, which the points (in it) absorb.
    as_vector(target.base_from_cam.Inverse() * source.base_from_cam * RigidFromTranslationRotvec(source_rho.data() + cam),
              rho.data() + cam);
    return rho;
  }
  // link_n_from_flange_t flange_from_cam_t Exp(c_t) = link_n_from_flange_s flange_from_cam_s Exp(c_s).
  as_vector((target.link_n_from_flange * target.flange_from_cam).Inverse() * source.link_n_from_flange *
                source.flange_from_cam * RigidFromTranslationRotvec(source_rho.data() + cam),
            rho.data() + cam);
  return rho;
}

}  // namespace selfcal::bundle
