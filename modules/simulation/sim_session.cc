#include "simulation/sim_session.h"

#include <limits>
#include <memory>

#include "sim/image_renderer.h"

namespace selfcal::simulation {

std::vector<tracking::PreviousDot> TruthIdentifier::Name(const tracking::DetectionReport& detections,
                                                          const std::vector<int>& ids) const {
  std::vector<Eigen::Vector2d> centroids;
  for (const tracking::DotDetection& d : detections.dots) centroids.push_back(d.centroid_px);
  const std::vector<int> names = sim::NameByNearestDisc(camera_->last_render(), centroids, match_radius_px_, ids);
  std::vector<tracking::PreviousDot> named;
  for (size_t k = 0; k < names.size(); ++k) {
    if (names[k] >= 0) named.push_back(tracking::MakePreviousDot(names[k], detections.dots[k]));
  }
  return named;
}

Result<std::vector<tracking::PreviousDot>> TruthIdentifier::Identify(const capture::Frame& /*frame*/,
                                                                     const tracking::DetectionReport& detections) {
  std::vector<tracking::PreviousDot> named = Name(detections, {});
  if (named.empty()) return Status::Error(ErrorCode::kDegenerateData, "no detection matches a rendered dot");
  return named;
}

std::vector<tracking::PreviousDot> TruthIdentifier::FindMarked(const capture::Frame& /*frame*/,
                                                               const tracking::DetectionReport& detections,
                                                               const std::vector<int>& missing_ids) {
  return Name(detections, missing_ids);
}

namespace {

// The dots a real scene would mark (the yardsticks' ends): TruthIdentifier::FindMarked names them anywhere.
std::vector<int> MarkedDots(const sim::SimResult& world) {
  std::vector<int> marked;
  for (const KnownDistance& y : world.observations.yardsticks) {
    marked.push_back(y.dot_a);
    marked.push_back(y.dot_b);
  }
  return marked;
}

}  // namespace

Result<SimCell> MakeSimCell(const RobotModel& nominal, const std::vector<acquisition::PlannedPose>& plan,
                            const SimCellOptions& options, const Eigen::VectorXd& start_joints_rad,
                            double start_time_s) {
  SimCell cell;
  std::vector<Eigen::VectorXd> joints;
  int num_identification = 0;
  for (const acquisition::PlannedPose& p : plan) {
    joints.push_back(p.joints_rad);
    num_identification += p.role == PoseRole::kIdentification ? 1 : 0;
  }
  sim::SimOptions world_options = options.world;
  world_options.num_identification_poses = num_identification;
  if (world_options.separation_dot_radius_m <= 0) world_options.separation_dot_radius_m = sim::kDefaultDotRadiusM;
  cell.world = std::make_unique<sim::SimResult>(sim::Simulate(nominal, joints, world_options));
  if (!cell.world->ok) return Status::Error(ErrorCode::kDegenerateData, "simulation: " + cell.world->message);

  RestartSimCell(&cell, options, start_joints_rad, start_time_s);
  return cell;
}

void RestartSimCell(SimCell* cell, const SimCellOptions& options, const Eigen::VectorXd& start_joints_rad,
                    double start_time_s) {
  cell->identifier.reset();  // refers to the camera,
  cell->camera.reset();      // whose pose function refers to the robot,
  cell->robot.reset();       // which refers to the clock
  const RobotModel& nominal = cell->world->truth.nominal;
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
  cell->clock = std::make_unique<robot::SimulatedClock>(start_time_s);
  cell->robot = std::make_unique<robot::SimulatedRobot>(robot_options, *cell->clock);

  sim::SimulatedCameraOptions camera_options = options.camera;
  camera_options.render.noise_seed = options.world.noise_seed;
  cell->camera = std::make_unique<sim::SimulatedCamera>(
      cell->world->truth.camera_true, sim::MakeDotScene(cell->world->truth), camera_options);
  const sim::SimTruth* truth = &cell->world->truth;
  const robot::SimulatedRobot* arm = cell->robot.get();
  cell->camera->SetPoseFunction(
      [truth, arm](double t) { return PointsFromCam(truth->nominal, truth->rho_true, arm->JointsAt(t)); });
  cell->identifier = std::make_unique<TruthIdentifier>(cell->camera.get(), MarkedDots(*cell->world));
}

void FollowReportedJoints(SimCell* cell, const SimCellOptions& options, robot::Robot* robot,
                          const Eigen::VectorXd& start_joints_rad) {
  cell->identifier.reset();  // refers to the camera
  cell->camera.reset();
  cell->robot.reset();
  sim::SimulatedCameraOptions camera_options = options.camera;
  camera_options.render.noise_seed = options.world.noise_seed;
  camera_options.real_time = true;
  cell->camera = std::make_unique<sim::SimulatedCamera>(
      cell->world->truth.camera_true, sim::MakeDotScene(cell->world->truth), camera_options);
  const sim::SimTruth* truth = &cell->world->truth;
  auto joints = std::make_shared<Eigen::VectorXd>(start_joints_rad);
  cell->camera->SetPoseFunction([truth, robot, joints](double /*exposure_s*/) {
    Result<robot::JointReading> reading = robot->ReadJoints();
    if (reading.ok() && reading->position_rad.size() == joints->size() && reading->position_rad.allFinite()) {
      *joints = reading->position_rad;
    }
    return PointsFromCam(truth->nominal, truth->rho_true, *joints);
  });
  cell->identifier = std::make_unique<TruthIdentifier>(cell->camera.get(), MarkedDots(*cell->world));
}

ObservationSet SimSetup(const SimCell& cell) {
  ObservationSet setup = cell.world->observations;
  setup.poses.clear();
  return setup;
}

}  // namespace selfcal::simulation
