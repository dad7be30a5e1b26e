#include "support/eye_to_hand_world.h"

#include <random>
#include <string>

#include <gtest/gtest.h>

#include "camera/camera.h"
#include "identification/identifiability.h"

namespace selfcal::testing {

namespace {

Eigen::VectorXd HomeJoints(const RobotModel& robot) {
  Eigen::VectorXd q = Eigen::VectorXd::Constant(robot.num_joints(), 0.3);
  if (robot.name == "puma560") q << 0.2, 0.6, -1.0, 0.3, 0.9, 0.1;
  if (robot.name == "ur5e") q << 0.3, -1.2, 1.5, -1.0, -1.3, 0.2;
  if (robot.name == "panda") q << 0.1, -0.4, 0.1, -2.0, 0.2, 1.8, 0.6;
  return q;
}

// 1280 x 1024 px, f_x 1400 px, no lens distortion.
CameraIntrinsics Camera() { return CameraIntrinsics{1280, 1024, 1400.0, 1.0, 639.5, 511.5}; }

// Dots on a 5-wide grid over a 160 x 100 mm plate 20 mm above the flange, jittered by up to 3 mm; every
// fourth raised by 20-40 mm.
std::vector<Eigen::Vector3d> PlateDots(int count, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> dots;
  if (count <= 5) {
    const double h = 0.05;
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(-h, -h, 0.02), Eigen::Vector3d(h, -h, 0.02), Eigen::Vector3d(h, h, 0.02),
                                     Eigen::Vector3d(-h, h, 0.02), Eigen::Vector3d(0, 0, 0.02)}) {
      if (static_cast<int>(dots.size()) < count) dots.push_back(p);
    }
    return dots;
  }
  const int rows = (count + 4) / 5;
  for (int i = 0; i < count; ++i) {
    const double x = -0.08 + 0.04 * (i % 5), y = rows > 1 ? -0.05 + 0.1 * (i / 5) / (rows - 1) : 0.0;
    double z = 0.02;
    if (i % 4 == 1) z += 0.03 + 0.01 * u(*rng);
    dots.emplace_back(x + 0.003 * u(*rng), y + 0.003 * u(*rng), z);
  }
  return dots;
}

bool AllInView(const CameraIntrinsics& camera, const Rigid3& cam_from_flange, const std::vector<Eigen::Vector3d>& dots,
               double margin_px) {
  for (const Eigen::Vector3d& d : dots) {
    const std::optional<Eigen::Vector2d> uv = Project(camera, cam_from_flange * d);
    if (!uv || !InImage(camera, *uv, margin_px)) return false;
  }
  return true;
}

// Joint poses whose flange pose is the home pose turned by up to 35 deg and moved by up to 100 mm per
// axis, every dot in view of the nominal camera with a 60 px margin.
std::vector<Eigen::VectorXd> FindPoses(const RobotModel& robot, const Eigen::VectorXd& home, const Rigid3& base_from_cam,
                                       const CameraIntrinsics& camera, const std::vector<Eigen::Vector3d>& dots,
                                       int count, std::mt19937_64* rng) {
  RobotModel flange_ik = robot;  // IK of the flange itself: an eye-in-hand copy with the camera on the flange
  flange_ik.mount = CameraMount::kEyeInHand;
  flange_ik.flange_from_cam = Rigid3();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
  const Rigid3 home_flange = BaseFromFlange(robot, rho, home);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::VectorXd> poses;
  for (int attempt = 0; attempt < 2000 && static_cast<int>(poses.size()) < count; ++attempt) {
    Eigen::Vector3d axis(u(*rng), u(*rng), u(*rng));
    if (axis.norm() < 1e-3) continue;
    const Eigen::Vector3d turn = axis.normalized() * (35.0 * kPi / 180) * std::abs(u(*rng));
    const Eigen::Vector3d move(0.1 * u(*rng), 0.1 * u(*rng), 0.1 * u(*rng));
    const Rigid3 target(home_flange.rotation * ExpSO3<double>(turn), home_flange.translation + move);
    Eigen::VectorXd q;
    if (!SolveCameraIk(flange_ik, rho, target, home, &q) || !WithinLimits(robot, q, 0.05)) continue;
    if (!AllInView(camera, base_from_cam.Inverse() * target, dots, 60)) continue;
    poses.push_back(q);
  }
  return poses;
}

// The rho entries that the poses identify (eye-in-hand analysis of the same chain) moved by the hidden
// errors, and the camera correction by its own.
void Perturb(const RobotModel& robot, const std::vector<Eigen::VectorXd>& poses, const EyeToHandOptions& options,
             std::mt19937_64* rng, EyeToHandWorld* world) {
  const KinematicParameters params(robot.num_joints());
  world->rho_true = KinematicParameters::Nominal(robot);
  if (robot.num_joints() > 0) {
    RobotModel in_hand = robot;
    in_hand.mount = CameraMount::kEyeInHand;
    world->perturbed_indices =
        identification::AnalyzeIdentifiability(in_hand, world->rho_true, poses, 0, {}).free_indices;
  } else {
    for (int i = params.CamOffset(); i < params.size(); ++i) world->perturbed_indices.push_back(i);
  }
  std::uniform_real_distribution<double> size(0.2, 1.0);
  std::bernoulli_distribution sign(0.5);
  for (int i : world->perturbed_indices) {
    const bool cam = i >= params.CamOffset();
    const bool length = params.kind(i) == ParameterKind::kLength;
    const double scale = cam ? (length ? options.cam_length_error_m : options.cam_angle_error_rad)
                             : (length ? options.length_error_m : options.angle_error_rad);
    world->rho_true[i] += (sign(*rng) ? 1 : -1) * scale * size(*rng);
  }
}

}  // namespace

RobotModel Panda() {
  const double h = kPi / 2;
  const std::vector<DhRow> rows = {{0, 0, 0.333, 0},     {0, -h, 0, 0},     {0, h, 0.316, 0}, {0.0825, h, 0, 0},
                                   {-0.0825, -h, 0.384, 0}, {0, h, 0, 0}, {0.088, h, 0, 0}};
  const std::vector<JointLimits> limits = {{-2.8973, 2.8973}, {-1.7628, 1.7628}, {-2.8973, 2.8973}, {-3.0718, -0.0698},
                                           {-2.8973, 2.8973}, {-0.0175, 3.7525}, {-2.8973, 2.8973}};
  RobotModel model = RobotModel::FromDh("panda", DhConvention::kModified, rows, limits, Rigid3(),
                                        Rigid3(RotZ(h), Eigen::Vector3d(0.04, 0, 0.06)));
  model.link_n_from_flange = Rigid3::FromTranslation(Eigen::Vector3d(0, 0, 0.107));
  return model;
}

EyeToHandOptions TagFlangePoseOptions(double noise_px, uint64_t seed) {
  EyeToHandOptions options;
  options.noise_px = noise_px;
  options.num_poses = 8;
  options.num_dots = 5;
  options.camera_distance_m = 0.5;
  options.flange_poses = true;
  options.seed = seed;
  return options;
}

EyeToHandWorld MakeEyeToHandWorld(const RobotModel& nominal, const EyeToHandOptions& options) {
  EyeToHandWorld world;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u(-1, 1);
  RobotModel robot = nominal;
  robot.mount = CameraMount::kEyeToHand;
  const Eigen::VectorXd home = HomeJoints(robot);
  const Rigid3 home_flange = BaseFromFlange(robot, KinematicParameters::Nominal(robot), home);
  // The camera on the home flange's z axis, looking back at the plate (its z along -z of the flange).
  robot.base_from_cam = Rigid3(home_flange.rotation * RotX(kPi),
                               home_flange * Eigen::Vector3d(0, 0, 0.02 + options.camera_distance_m));
  const CameraIntrinsics camera = Camera();
  world.dots_in_flange = PlateDots(options.num_dots, &rng);
  const int count = options.num_poses + options.num_verification;
  const std::vector<Eigen::VectorXd> poses =
      FindPoses(robot, home, robot.base_from_cam, camera, world.dots_in_flange, count, &rng);
  if (static_cast<int>(poses.size()) < count) {
    ADD_FAILURE() << robot.name << ": found " << poses.size() << " of " << count << " poses";
    return world;
  }
  Perturb(robot, std::vector<Eigen::VectorXd>(poses.begin(), poses.begin() + options.num_poses), options, &rng, &world);
  world.camera_true = camera;
  world.camera_true.fx_px *= 1.0 + options.fx_relative_error * u(rng);
  world.base_from_cam_true = BaseFromCam(robot, world.rho_true, Eigen::VectorXd());
  ObservationSet& set = world.observations;
  set.camera = camera;
  set.pixel_noise_px = options.noise_px > 0 ? options.noise_px : 0.3;
  for (size_t p = 0; p < poses.size(); ++p) {
    world.base_from_flange_true.push_back(BaseFromFlange(robot, world.rho_true, poses[p]));
    PoseObservation pose;
    pose.id = "p" + std::to_string(p);
    pose.joints_rad = poses[p];
    if (static_cast<int>(p) >= options.num_poses) pose.role = PoseRole::kVerification;
    if (options.flange_poses) {
      pose.joints_rad = Eigen::VectorXd();
      pose.base_from_flange = world.base_from_flange_true.back();
    }
    set.poses.push_back(pose);
  }
  const int last = options.num_dots - 1;
  const KnownDistance yardstick{0, last, (world.dots_in_flange[0] - world.dots_in_flange[last]).norm()};
  if (options.num_verification > 0 && options.num_dots > 3) {
    const int a = 2, b = options.num_dots - 3;
    set.check_distances.push_back({a, b, (world.dots_in_flange[a] - world.dots_in_flange[b]).norm()});
  }
  if (options.flange_poses) {
    // No joints: the hand-eye problem of the fixed camera, the true flange poses recorded.
    RobotModel flange_model = FlangePoseModel(Rigid3());
    flange_model.mount = CameraMount::kEyeToHand;
    flange_model.base_from_cam = robot.base_from_cam;
    const KinematicParameters params(0);
    Eigen::VectorXd rho = KinematicParameters::Nominal(flange_model);
    rho.segment<6>(params.CamOffset()) = world.rho_true.segment<6>(KinematicParameters(robot.num_joints()).CamOffset());
    world.rho_true = rho;
    world.perturbed_indices.clear();
    for (int i = params.CamOffset(); i < params.size(); ++i) world.perturbed_indices.push_back(i);
    set.robot = flange_model;
    set.check_distances.push_back(yardstick);
  } else {
    set.robot = robot;
    set.yardsticks.push_back(yardstick);
  }
  set = ReobserveEyeToHand(world, options.noise_px, options.noise_seed);
  return world;
}

ObservationSet ReobserveEyeToHand(const EyeToHandWorld& world, double noise_px, uint64_t noise_seed) {
  ObservationSet set = world.observations;
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> gauss(0, 1);
  const Rigid3 cam_from_base = world.base_from_cam_true.Inverse();
  for (size_t p = 0; p < set.poses.size(); ++p) {
    set.poses[p].dots_px.clear();
    for (size_t d = 0; d < world.dots_in_flange.size(); ++d) {
      const std::optional<Eigen::Vector2d> uv =
          Project(world.camera_true, cam_from_base * world.base_from_flange_true[p] * world.dots_in_flange[d]);
      const Eigen::Vector2d noise(gauss(rng), gauss(rng));
      if (!uv || !InImage(world.camera_true, *uv, 5)) {
        ADD_FAILURE() << "dot " << d << " leaves the image at pose " << p;
        continue;
      }
      set.poses[p].dots_px[static_cast<int>(d)] = *uv + noise_px * noise;
    }
  }
  return set;
}

}  // namespace selfcal::testing
