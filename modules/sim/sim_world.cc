#include "sim/sim_world.h"

#include <cmath>
#include <random>
#include <sstream>

#include "identification/identifiability.h"

namespace selfcal::sim {

std::string SimOptions::Validate() const {
  std::ostringstream out;
  out << camera.Validate();
  auto non_negative = [&](double v, const char* name) {
    if (!std::isfinite(v) || v < 0) out << name << " = " << v << " must be finite and >= 0\n";
  };
  non_negative(length_error_std_m, "length_error_std_m");
  non_negative(angle_error_std_rad, "angle_error_std_rad");
  non_negative(cam_length_error_std_m, "cam_length_error_std_m");
  non_negative(cam_angle_error_std_rad, "cam_angle_error_std_rad");
  non_negative(fx_relative_error_std, "fx_relative_error_std");
  non_negative(pixel_noise_px, "pixel_noise_px");
  non_negative(joint_noise_rad, "joint_noise_rad");
  if (!(fx_nominal_px > 0)) out << "fx_nominal_px = " << fx_nominal_px << " must be > 0\n";
  if (sheet_grid.rows > 0 || sheet_grid.cols > 0) {
    if (!flat_sheet) out << "sheet_grid needs flat_sheet\n";
    if (sheet_grid.rows < 2 || sheet_grid.cols < 2 || sheet_grid.rows * sheet_grid.cols < 8) {
      out << "sheet_grid " << sheet_grid.rows << " x " << sheet_grid.cols << " must have rows, cols >= 2 and >= 8 dots\n";
    }
    if (!(sheet_grid.spacing_m > 0) || !std::isfinite(sheet_grid.spacing_m)) out << "sheet_grid.spacing_m must be > 0\n";
    if (!(sheet_grid.origin_radius_scale >= 1) || !std::isfinite(sheet_grid.origin_radius_scale)) {
      out << "sheet_grid.origin_radius_scale must be finite and >= 1\n";
    }
  } else if (num_dots < 8) {
    out << "num_dots = " << num_dots << " must be >= 8\n";
  }
  if (!(yardstick_length_m > 0)) out << "yardstick_length_m must be > 0\n";
  if (num_identification_poses < 2) out << "num_identification_poses must be >= 2\n";
  non_negative(separation_dot_radius_m, "separation_dot_radius_m");
  non_negative(min_rim_gap_diameters, "min_rim_gap_diameters");
  if (!(plate.half_size_m > 0) || !std::isfinite(plate.half_size_m)) out << "plate.half_size_m must be > 0\n";
  non_negative(plate.standoff_m, "plate.standoff_m");
  non_negative(plate.raised_m, "plate.raised_m");
  if (plate.raised_every < 1) out << "plate.raised_every must be >= 1\n";
  if (plate.num_dots < 8) out << "plate.num_dots = " << plate.num_dots << " must be >= 8\n";
  if (!(plate.yardstick_length_m > 0) || !(plate.yardstick_length_m < 2 * std::sqrt(2.0) * plate.half_size_m)) {
    out << "plate.yardstick_length_m must be > 0 and fit on the plate\n";
  }
  return out.str();
}

namespace {

bool Visible(const CameraIntrinsics& camera, const Rigid3& base_from_cam, const Eigen::Vector3d& p_in_base,
             double margin_px, double min_depth_m) {
  const Eigen::Vector3d p_in_cam = base_from_cam.Inverse() * p_in_base;
  if (p_in_cam.z() < min_depth_m) return false;
  const auto uv = Project(camera, p_in_cam);
  return uv && InImage(camera, *uv, margin_px);
}

// Least-squares point closest to all optical axes: where the cameras look.
Eigen::Vector3d ConvergencePoint(const std::vector<Rigid3>& cams) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Rigid3& c : cams) {
    const Eigen::Vector3d z = c.rotation.col(2);
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - z * z.transpose();
    a += p;
    b += p * c.translation;
  }
  return a.ldlt().solve(b);
}

ObservationSet Observe(const SimResult& world, const std::vector<Eigen::VectorXd>& joints, double noise_px,
                       uint64_t noise_seed, int num_identification, double joint_noise_rad = 0) {
  ObservationSet set;
  set.robot = world.truth.nominal;
  set.camera = world.truth.camera_true;
  set.camera.fx_px = world.observations.camera.fx_px;  // the prior, not the truth
  set.pixel_noise_px = noise_px > 0 ? noise_px : 0.1;
  set.yardsticks = world.observations.yardsticks;
  set.check_distances = world.observations.check_distances;
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::mt19937_64 joint_rng(noise_seed ^ 0x6a6f696e74ULL);
  for (size_t i = 0; i < joints.size(); ++i) {
    PoseObservation pose;
    pose.id = (i < 10 ? "p0" : "p") + std::to_string(i);
    pose.role = static_cast<int>(i) < num_identification ? PoseRole::kIdentification : PoseRole::kVerification;
    pose.joints_rad = joints[i];
    if (joint_noise_rad > 0) {
      for (Eigen::Index j = 0; j < pose.joints_rad.size(); ++j) pose.joints_rad[j] += joint_noise_rad * noise(joint_rng);
    }
    const Rigid3 cam_from_base = world.truth.base_from_cam[i].Inverse();
    for (size_t d = 0; d < world.truth.dots_in_base.size(); ++d) {
      const auto uv = Project(world.truth.camera_true, cam_from_base * world.truth.dots_in_base[d]);
      const double du = noise(rng), dv = noise(rng);  // drawn for every dot: same stream at any level
      const Eigen::Vector2d detected = *uv + noise_px * Eigen::Vector2d(du, dv);
      // A detector reports no centre outside the image: a dot the noise moves out is not seen (at the
      // larger noises of the documented range, up to 10 px, some dots near the border are).
      if (InImage(world.truth.camera_true, detected, 0.0)) pose.dots_px[static_cast<int>(d)] = detected;
    }
    set.poses.push_back(std::move(pose));
  }
  return set;
}

// Hidden kinematic errors into truth->rho_true, on the identifiable parameters unless asked otherwise,
// and the true focal. Draws from `rng` through `gauss` in a fixed order (the world's stream).
void PerturbModel(const RobotModel& nominal, const std::vector<Eigen::VectorXd>& trajectory, const SimOptions& options,
                  std::mt19937_64* rng, std::normal_distribution<double>* gauss, SimTruth* truth) {
  const KinematicParameters params(nominal.num_joints());
  const Eigen::VectorXd rho_nominal = KinematicParameters::Nominal(nominal);
  std::vector<int> to_perturb;
  if (options.perturb_gauge_parameters) {
    for (int i = 0; i < params.size(); ++i) to_perturb.push_back(i);
  } else {
    std::vector<Eigen::VectorXd> id_poses(trajectory.begin(), trajectory.begin() + options.num_identification_poses);
    identification::IdentifiabilityOptions id_options;
    to_perturb = identification::AnalyzeIdentifiability(nominal, rho_nominal, id_poses, 0, id_options).free_indices;
  }
  truth->rho_true = rho_nominal;
  std::vector<double> draws(params.size());
  for (double& d : draws) d = (*gauss)(*rng);  // one draw per parameter whatever is perturbed: stable streams
  for (int i : to_perturb) {
    const bool cam = i >= params.CamOffset();
    const bool length = params.kind(i) == ParameterKind::kLength;
    const double std_dev = cam ? (length ? options.cam_length_error_std_m : options.cam_angle_error_std_rad)
                               : (length ? options.length_error_std_m : options.angle_error_std_rad);
    truth->rho_true[i] += std_dev * draws[i];
  }
  truth->perturbed_indices = to_perturb;
  truth->camera_true = options.camera;
  truth->camera_true.fx_px = options.fx_nominal_px * (1.0 + options.fx_relative_error_std * (*gauss)(*rng));
}

// Scene: rejection sampling in a box around where the cameras look, every dot in every view. Dots 0
// and 1 are the yardstick's ends. Appends to truth->dots_in_base, drawing from the world's stream.
class ScenePlacer {
 public:
  ScenePlacer(const SimOptions& options, SimTruth* truth, std::mt19937_64* rng, std::normal_distribution<double>* gauss)
      : options_(options), truth_(*truth), rng_(*rng), gauss_(*gauss), placed_(truth->base_from_cam.size()),
        spaced_(options.separation_dot_radius_m > 0) {
    for (const Rigid3& c : truth_.base_from_cam) cam_from_base_.push_back(c.Inverse());
  }

  void Place(const Eigen::Vector3d& centre, CameraMount mount) {
    if (mount == CameraMount::kEyeToHand) {
      PlaceOnPlate();
    } else if (options_.HasSheetGrid()) {
      PlaceGrid(centre);
    } else if (options_.flat_sheet) {
      PlaceOnSheet(centre);
    } else {
      PlaceInVolume(centre);
    }
  }

 private:
  static constexpr int kMaxTries = 200000;
  static constexpr double kHalfSize = 0.3;  // m, of the box around the centre

  // Per view, the projected centre and radius (px) of every dot placed so far (spacing rule only).
  struct Disc {
    Eigen::Vector2d uv;
    double radius_px;
  };

  bool VisibleEverywhere(const Eigen::Vector3d& p) const {
    for (size_t v = 0; v < truth_.base_from_cam.size(); ++v) {
      if (!Visible(truth_.camera_true, truth_.base_from_cam[v], p, options_.image_margin_px, options_.min_depth_m)) {
        return false;
      }
      if (!spaced_) continue;
      const Eigen::Vector3d pc = cam_from_base_[v] * p;
      const Eigen::Vector2d uv = *Project(truth_.camera_true, pc);
      const double r = truth_.camera_true.fx_px * options_.separation_dot_radius_m / pc.z();
      for (const Disc& d : placed_[v]) {
        const double gap = (uv - d.uv).norm() - r - d.radius_px;
        if (gap < options_.min_rim_gap_diameters * 2.0 * std::max(r, d.radius_px)) return false;
      }
    }
    return true;
  }

  // Records p's discs for the spacing rule (call after accepting p).
  void Record(const Eigen::Vector3d& p) {
    truth_.dots_in_base.push_back(p);
    if (!spaced_) return;
    for (size_t v = 0; v < truth_.base_from_cam.size(); ++v) {
      const Eigen::Vector3d pc = cam_from_base_[v] * p;
      placed_[v].push_back({*Project(truth_.camera_true, pc),
                            truth_.camera_true.fx_px * options_.separation_dot_radius_m / pc.z()});
    }
  }

  // The yardstick's two ends, checked against each other as well.
  void PlacePair(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    if (!VisibleEverywhere(a)) return;
    Record(a);
    if (VisibleEverywhere(b)) {
      Record(b);
      return;
    }
    truth_.dots_in_base.clear();
    for (auto& view : placed_) view.clear();
  }

  // The sheet's in-plane axes e1, e2: orthonormal, perpendicular to the mean optical axis n, e1 x e2 = n.
  void SheetAxes(Eigen::Vector3d* e1, Eigen::Vector3d* e2) const {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (const Rigid3& c : truth_.base_from_cam) n += c.rotation.col(2);
    n.normalize();
    const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    *e1 = n.cross(helper).normalized();
    *e2 = n.cross(*e1);
  }

  // The grid centred on `centre`: +col along e1, +row along -e2, so that col x row = -n points from the
  // sheet towards the cameras (the printed face's normal). All or nothing: a dot out of any view clears it.
  void PlaceGrid(const Eigen::Vector3d& centre) {
    Eigen::Vector3d e1, e2;
    SheetAxes(&e1, &e2);
    const SimOptions::SheetGrid& g = options_.sheet_grid;
    const Eigen::Vector3d col_step = g.spacing_m * e1, row_step = -g.spacing_m * e2;
    const Eigen::Vector3d origin = centre - 0.5 * (g.cols - 1) * col_step - 0.5 * (g.rows - 1) * row_step;
    for (int row = 0; row < g.rows; ++row) {
      for (int col = 0; col < g.cols; ++col) {
        const Eigen::Vector3d p = origin + col * col_step + row * row_step;
        if (!VisibleEverywhere(p)) {
          truth_.dots_in_base.clear();
          return;
        }
        Record(p);
      }
    }
    truth_.dot_radius_scale.assign(truth_.dots_in_base.size(), 1.0);
    truth_.dot_radius_scale[0] = g.origin_radius_scale;
  }

  void PlaceOnSheet(const Eigen::Vector3d& centre) {
    std::uniform_real_distribution<double> uniform(-kHalfSize, kHalfSize);
    int tries = 0;
    Eigen::Vector3d e1, e2;
    SheetAxes(&e1, &e2);
    auto on_sheet = [&](double u, double v) { return Eigen::Vector3d(centre + u * e1 + v * e2); };
    std::mt19937_64& rng = rng_;
    std::normal_distribution<double>& gauss = gauss_;
    while (truth_.dots_in_base.size() < 2 && tries < kMaxTries) {
      ++tries;
      const double mu = 0.3 * uniform(rng), mv = 0.3 * uniform(rng);
      const Eigen::Vector2d dir = Eigen::Vector2d(gauss(rng), gauss(rng)).normalized();
      const double h = 0.5 * options_.yardstick_length_m;
      const Eigen::Vector3d a = on_sheet(mu - h * dir.x(), mv - h * dir.y());
      const Eigen::Vector3d b = on_sheet(mu + h * dir.x(), mv + h * dir.y());
      PlacePair(a, b);
    }
    while (static_cast<int>(truth_.dots_in_base.size()) < options_.num_dots && tries < kMaxTries) {
      ++tries;
      const Eigen::Vector3d p = on_sheet(uniform(rng), uniform(rng));
      if (VisibleEverywhere(p)) Record(p);
    }
  }

  // Eye-to-hand: on the plate carried by the flange (SimOptions::Plate), in the flange frame; the yardstick's
  // ends on the face, every raised_every-th further dot raised above it.
  void PlaceOnPlate() {
    const SimOptions::Plate& plate = options_.plate;
    std::uniform_real_distribution<double> uniform(-plate.half_size_m, plate.half_size_m);
    auto on_face = [&](double u, double v) { return Eigen::Vector3d(u, v, plate.standoff_m); };
    auto inside = [&](const Eigen::Vector3d& p) {
      return std::abs(p.x()) <= plate.half_size_m && std::abs(p.y()) <= plate.half_size_m;
    };
    int tries = 0;
    while (truth_.dots_in_base.size() < 2 && tries < kMaxTries) {
      ++tries;
      const double angle = kPi * uniform(rng_) / plate.half_size_m;
      const Eigen::Vector3d half = 0.5 * plate.yardstick_length_m * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0);
      const Eigen::Vector3d mid = on_face(0.5 * uniform(rng_), 0.5 * uniform(rng_));
      if (inside(mid - half) && inside(mid + half)) PlacePair(mid - half, mid + half);
    }
    while (static_cast<int>(truth_.dots_in_base.size()) < plate.num_dots && tries < kMaxTries) {
      ++tries;
      Eigen::Vector3d p = on_face(uniform(rng_), uniform(rng_));
      const int placed = static_cast<int>(truth_.dots_in_base.size()) - 2;
      if (placed % plate.raised_every == plate.raised_every - 1) p.z() += plate.raised_m;
      if (VisibleEverywhere(p)) Record(p);
    }
  }

  void PlaceInVolume(const Eigen::Vector3d& centre) {
    std::uniform_real_distribution<double> uniform(-kHalfSize, kHalfSize);
    int tries = 0;
    std::mt19937_64& rng = rng_;
    std::normal_distribution<double>& gauss = gauss_;
    // The yardstick: dots 0 and 1, yardstick_length_m apart along a random direction through the centre.
    while (truth_.dots_in_base.size() < 2 && tries < kMaxTries) {
      ++tries;
      const Eigen::Vector3d mid = centre + 0.3 * Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
      const Eigen::Vector3d dir = Eigen::Vector3d(gauss(rng), gauss(rng), 0.3 * gauss(rng)).normalized();
      const Eigen::Vector3d a = mid - 0.5 * options_.yardstick_length_m * dir;
      const Eigen::Vector3d b = mid + 0.5 * options_.yardstick_length_m * dir;
      PlacePair(a, b);
    }
    while (static_cast<int>(truth_.dots_in_base.size()) < options_.num_dots && tries < kMaxTries) {
      ++tries;
      const Eigen::Vector3d p = centre + Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
      if (VisibleEverywhere(p)) Record(p);
    }
  }

  const SimOptions& options_;
  SimTruth& truth_;
  std::mt19937_64& rng_;
  std::normal_distribution<double>& gauss_;
  std::vector<std::vector<Disc>> placed_;
  const bool spaced_;
  std::vector<Rigid3> cam_from_base_;
};

}  // namespace

Rigid3 FixedCameraTruth(const SimTruth& truth) {
  return BaseFromCam(truth.nominal, truth.rho_true, Eigen::VectorXd::Zero(truth.nominal.num_joints()));
}

Rigid3 DefaultFixedCamera(const RobotModel& robot, const Eigen::VectorXd& home_joints_rad, double distance_m) {
  const Rigid3 flange = BaseFromFlange(robot, KinematicParameters::Nominal(robot), home_joints_rad);
  const Eigen::Matrix3d r = flange.rotation * RotX(kPi);  // z towards the flange, x along the flange's x
  return Rigid3(r, flange.translation + distance_m * flange.rotation.col(2));
}

std::vector<KnownDistance> CheckPairs(const std::vector<Eigen::Vector3d>& dots) {
  std::vector<KnownDistance> pairs;
  const int half = static_cast<int>(dots.size()) / 2;
  for (int i = 0; i < half; ++i) pairs.push_back({i, i + half, (dots[i] - dots[i + half]).norm()});
  return pairs;
}

SimResult Simulate(const RobotModel& nominal, const std::vector<Eigen::VectorXd>& trajectory,
                   const SimOptions& options) {
  SimResult result;
  const std::string problems = options.Validate();
  if (!problems.empty()) {
    result.message = "invalid simulation options:\n" + problems;
    return result;
  }
  if (static_cast<int>(trajectory.size()) <= options.num_identification_poses) {
    result.message = "the trajectory has " + std::to_string(trajectory.size()) + " poses; more than " +
                     std::to_string(options.num_identification_poses) + " are needed (identification + verification)";
    return result;
  }
  for (size_t i = 0; i < trajectory.size(); ++i) {
    if (!WithinLimits(nominal, trajectory[i])) {
      result.message = "trajectory pose " + std::to_string(i) + " is outside the joint limits";
      return result;
    }
  }
  std::mt19937_64 rng(options.world_seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  SimTruth& truth = result.truth;
  truth.nominal = nominal;
  truth.nominal.flange_from_cam = nominal.flange_from_cam;
  PerturbModel(nominal, trajectory, options, &rng, &gauss, &truth);
  for (const Eigen::VectorXd& q : trajectory) truth.base_from_cam.push_back(PointsFromCam(nominal, truth.rho_true, q));

  ScenePlacer(options, &truth, &rng, &gauss).Place(ConvergencePoint(truth.base_from_cam), nominal.mount);
  const bool plate = nominal.mount == CameraMount::kEyeToHand;  // the plate in place of any sheet
  const bool grid = options.HasSheetGrid() && !plate;
  const int num_dots = plate  ? options.plate.num_dots
                       : grid ? options.sheet_grid.rows * options.sheet_grid.cols
                              : options.num_dots;
  if (static_cast<int>(truth.dots_in_base.size()) < num_dots) {
    std::ostringstream m;
    if (grid) {
      m << "the " << options.sheet_grid.rows << " x " << options.sheet_grid.cols << " grid of "
        << 1e3 * options.sheet_grid.spacing_m << " mm does not fit in every view (margin " << options.image_margin_px
        << " px): choose fewer dots or a smaller spacing";
    } else {
      m << "could not place " << num_dots << " dots in view of every pose: the views share too little of the "
        << (plate ? "plate (does every pose keep it in the fixed camera's view?)" : "scene");
    }
    result.message = m.str();
    return result;
  }

  result.observations.camera = truth.camera_true;
  result.observations.camera.fx_px = options.fx_nominal_px;
  const int far_end = grid ? num_dots - 1 : 1;
  result.observations.yardsticks = {
      {0, far_end,
       grid    ? (truth.dots_in_base[0] - truth.dots_in_base[far_end]).norm()
       : plate ? options.plate.yardstick_length_m
               : options.yardstick_length_m}};
  result.observations.check_distances = CheckPairs(truth.dots_in_base);
  result.observations = Observe(result, trajectory, options.pixel_noise_px, options.noise_seed,
                                options.num_identification_poses, options.joint_noise_rad);
  result.ok = true;
  return result;
}

ObservationSet Reobserve(const SimResult& world, double pixel_noise_px, uint64_t noise_seed) {
  std::vector<Eigen::VectorXd> joints;
  int num_identification = 0;
  for (const PoseObservation& p : world.observations.poses) {
    joints.push_back(p.joints_rad);
    if (p.role == PoseRole::kIdentification) ++num_identification;
  }
  return Observe(world, joints, pixel_noise_px, noise_seed, num_identification);
}

}  // namespace selfcal::sim
