#include "simulation/detect_folder.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "io/pose_files.h"
#include "io/report_json.h"

namespace selfcal::simulation {

namespace {

nlohmann::json HiddenTruthJson(const sim::SimResult& world, const std::string& description) {
  const sim::SimTruth& truth = world.truth;
  const KinematicParameters params(truth.nominal.num_joints());
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(truth.nominal);
  nlohmann::json parameters = nlohmann::json::array();
  for (int i = 0; i < params.size(); ++i) {
    const std::string unit = params.kind(i) == ParameterKind::kLength ? "_m" : "_rad";
    const bool perturbed =
        std::find(truth.perturbed_indices.begin(), truth.perturbed_indices.end(), i) != truth.perturbed_indices.end();
    parameters.push_back({{"name", params.name(i)},
                          {"nominal" + unit, nominal[i]},
                          {"true" + unit, truth.rho_true[i]},
                          {"perturbed", perturbed}});
  }
  const Rigid3 flange_from_cam = ApplyParameters(truth.nominal, truth.rho_true).flange_from_cam;
  const Eigen::Vector3d w = LogSO3(flange_from_cam.rotation);
  const Eigen::Vector3d& t = flange_from_cam.translation;
  return {{"format", "selfcal-sim-truth"},
          {"version", 2},
          {"note", "hidden from the solver: the true model in the nominal model's parameterisation (base and cam are "
                   "corrections right-multiplied onto their nominal transforms)"},
          {"world", description},
          {"fx_px", truth.camera_true.fx_px},
          {"fx_nominal_px", world.observations.camera.fx_px},
          {"flange_from_cam", {{"xyz_m", {t.x(), t.y(), t.z()}}, {"rotvec_rad", {w.x(), w.y(), w.z()}}}},
          {"parameters", parameters}};
}

}  // namespace

Status WriteDetectFolder(const sim::SimResult& world, const sim::SequenceRenderOptions& options,
                         const std::string& folder) {
  sim::SequenceRenderOptions all = options;
  all.pose_indices.clear();
  sim::SequenceTruth rendered;
  if (Status s = sim::RenderSequenceFolder(world, all, folder, &rendered); !s.ok()) return s;
  std::vector<io::PosesListEntry> entries;
  for (const sim::SequenceTruthFrame& frame : rendered.frames) {
    const PoseObservation& pose = world.observations.poses[static_cast<size_t>(frame.pose_index)];
    entries.push_back({frame.image, pose.joints_rad, pose.role == PoseRole::kVerification});
  }
  const std::filesystem::path dir(folder);
  if (Status s = io::SavePosesList(entries, (dir / kDetectPosesName).string()); !s.ok()) return s;
  return io::WriteJsonFile(HiddenTruthJson(world, options.world_description), (dir / kHiddenTruthName).string());
}

}  // namespace selfcal::simulation
