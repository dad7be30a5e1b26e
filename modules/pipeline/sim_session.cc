#include "pipeline/sim_session.h"

#include <algorithm>
#include <limits>

#include "sim/image_renderer.h"

namespace selfcal::pipeline {

std::vector<std::pair<size_t, int>> TruthIdentifier::Match(const tracking::DetectionReport& detections,
                                                           const std::vector<int>& ids) const {
  const sim::RenderedImage& render = camera_->last_render();
  std::vector<int> claims(render.dots.size(), 0);
  std::vector<int> owner(detections.dots.size(), -1);
  for (size_t k = 0; k < detections.dots.size(); ++k) {
    double best = match_radius_px_;
    for (const sim::RenderedDot& dot : render.dots) {
      if (!dot.visible || (!ids.empty() && std::find(ids.begin(), ids.end(), dot.id) == ids.end())) continue;
      const double d = (detections.dots[k].centroid_px - dot.projected_centre_px).norm();
      if (d < best) {
        best = d;
        owner[k] = dot.id;
      }
    }
    if (owner[k] >= 0) ++claims[owner[k]];
  }
  std::vector<std::pair<size_t, int>> matches;
  for (size_t k = 0; k < detections.dots.size(); ++k) {
    if (owner[k] >= 0 && claims[owner[k]] == 1) matches.push_back({k, owner[k]});
  }
  return matches;
}

Result<std::vector<tracking::PreviousDot>> TruthIdentifier::Identify(const capture::Frame& /*frame*/,
                                                                     const tracking::DetectionReport& detections) {
  std::vector<tracking::PreviousDot> named;
  for (const auto& [k, id] : Match(detections, {})) named.push_back(tracking::MakePreviousDot(id, detections.dots[k]));
  if (named.empty()) return Status::Error(ExitCode::kDegenerateData, "no detection matches a rendered dot");
  return named;
}

std::vector<tracking::PreviousDot> TruthIdentifier::FindMarked(const capture::Frame& /*frame*/,
                                                               const tracking::DetectionReport& detections,
                                                               const std::vector<int>& missing_ids) {
  std::vector<tracking::PreviousDot> found;
  for (const auto& [k, id] : Match(detections, missing_ids)) found.push_back(tracking::MakePreviousDot(id, detections.dots[k]));
  return found;
}

Result<SimCell> MakeSimCell(const RobotModel& nominal, const std::vector<PlannedPose>& plan,
                            const SimCellOptions& options, const Eigen::VectorXd& start_joints_rad,
                            double start_time_s) {
  SimCell cell;
  std::vector<Eigen::VectorXd> joints;
  int num_identification = 0;
  for (const PlannedPose& p : plan) {
    joints.push_back(p.joints_rad);
    num_identification += p.role == PoseRole::kIdentification ? 1 : 0;
  }
  sim::SimOptions world_options = options.world;
  world_options.num_identification_poses = num_identification;
  if (world_options.separation_dot_radius_m <= 0) world_options.separation_dot_radius_m = sim::kDefaultDotRadiusM;
  cell.world = std::make_unique<sim::SimResult>(sim::Simulate(nominal, joints, world_options));
  if (!cell.world->ok) return Status::Error(ExitCode::kDegenerateData, "simulation: " + cell.world->message);

  const int n = nominal.num_joints();
  robot::SimulatedRobotOptions robot_options;
  robot_options.identity = {"simulated", nominal.name.empty() ? "simulated-arm" : nominal.name,
                            "sim-" + std::to_string(options.world.world_seed), "", false};
  robot_options.limits.lower_rad.resize(n);
  robot_options.limits.upper_rad.resize(n);
  for (int j = 0; j < n; ++j) {
    robot_options.limits.lower_rad[j] = nominal.limits[j].min_rad;
    robot_options.limits.upper_rad[j] = nominal.limits[j].max_rad;
  }
  robot_options.limits.max_velocity_rad_s = Eigen::VectorXd::Constant(n, options.max_velocity_rad_s);
  robot_options.initial_joints_rad = start_joints_rad;
  robot_options.ring_cutoff_s = options.ring_cutoff_s;
  robot_options.faults = options.faults;
  robot_options.seed = options.world.world_seed;
  cell.clock = std::make_unique<robot::SimulatedClock>(start_time_s);
  cell.robot = std::make_unique<robot::SimulatedRobot>(robot_options, *cell.clock);

  sim::SimulatedCameraOptions camera_options = options.camera;
  camera_options.render.noise_seed = options.world.noise_seed;
  cell.camera = std::make_unique<sim::SimulatedCamera>(
      cell.world->truth.camera_true, sim::MakeDotScene(cell.world->truth), camera_options);
  const sim::SimTruth* truth = &cell.world->truth;
  const robot::SimulatedRobot* arm = cell.robot.get();
  cell.camera->SetPoseFunction(
      [truth, arm](double t) { return BaseFromCam(truth->nominal, truth->rho_true, arm->JointsAt(t)); });
  std::vector<int> marked;
  for (const KnownDistance& y : cell.world->observations.yardsticks) {
    marked.push_back(y.dot_a);
    marked.push_back(y.dot_b);
  }
  cell.identifier = std::make_unique<TruthIdentifier>(cell.camera.get(), marked);
  return cell;
}

ObservationSet SimSetup(const SimCell& cell) {
  ObservationSet setup = cell.world->observations;
  setup.poses.clear();
  return setup;
}

}  // namespace selfcal::pipeline
