// Module sim (ARCHITECTURE.md): the simulated world with hidden truth (this header: robot errors, hand-eye,
// f_x, dots, pixel noise; a flat sheet of random dots or a modified circle grid with a larger origin dot);
// trajectory_generator.h (smooth arcs); image_renderer.h (perspective discs, supersampled with only the
// samples nearest the rim projected, blur, noise; per-dot truth incl. the ellipse-centre bias) over
// image_formation.h (coverage -> grey -> blur around the dots -> seeded ziggurat noise, frame buffers kept
// per thread); simulated_camera.h (SimulatedCamera, a capture::FrameSource); render_sequence.h (a simulated
// session rendered into a recorded sequence with its truth); board_renderer.h (a flat printed board:
// chessboard, ChArUco, any pattern as a grey level per board point, rendered anti-aliased through the lens,
// with known corners). Uses observations, identification, kinematics, camera, geometry, capture.
//
// The simulated world of ../shared/DESIGN.md section 6: a true robot (nominal + hidden errors drawn from a seed),
// a hidden flange-to-camera transform and focal length, a scene of non-coplanar dots (or, with
// flat_sheet, dots on one plane) in view of every pose, a yardstick, and image points projected with
// Gaussian pixel noise. The solver only ever sees the
// ObservationSet; the SimTruth is for scoring.
//
// Eye-to-hand (the nominal model's mount, kinematics/robot_model.h): the camera is fixed in the base frame at
// the hidden true base_from_cam (the nominal RobotModel::base_from_cam corrected by the hidden camera
// correction of rho) and the dots sit on a plate carried by the flange (SimOptions::Plate), at hidden
// positions in the flange frame, a few of them raised so that they are not coplanar. Every camera pose of
// the truth is then PointsFromCam, the camera in the flange frame, and the dots are in the flange frame:
// the renderer, the observations and the scoring see one frame of the points whichever the mount.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::sim {

struct SimOptions {
  uint64_t world_seed = 1;          // robot errors, camera, scene
  uint64_t noise_seed = 1;          // pixel noise
  // Hidden kinematic errors (../shared/DESIGN.md section 6): lengths ~ N(0, 1 mm), angles ~ N(0, 0.2 deg).
  double length_error_std_m = 1e-3;
  double angle_error_std_rad = DegToRad(0.2);
  // Hidden hand-eye error relative to the nominal flange_from_cam.
  double cam_length_error_std_m = 2e-3;
  double cam_angle_error_std_rad = DegToRad(0.5);
  // Parameters the relative measurements cannot see (base, joint 1, redundant ones) are a gauge: any
  // value yields identical images once the unknown dots are re-expressed. false leaves them at nominal
  // so that parameters can be compared one by one with the truth; true perturbs them as well.
  bool perturb_gauge_parameters = false;
  double fx_nominal_px = 1000.0;    // what the user believes (the prior)
  double fx_relative_error_std = 0.01;  // true f_x = nominal * (1 + N(0, this))
  CameraIntrinsics camera;          // size, mu, principal point, k1 of the true camera
  int num_dots = 80;
  double image_margin_px = 10.0;    // every dot at least this far inside every image
  double min_depth_m = 0.3;
  double yardstick_length_m = 0.2;  // dots 0 and 1 are placed this far apart
  // A flat dot sheet: every dot (the yardstick's two included) on the plane through the point the cameras
  // look at, facing the mean viewing direction (normal = mean optical axis), still in view of every
  // pose. The paper's factor method is degenerate there; the kinematic bundle adjustment is not.
  bool flat_sheet = false;
  // With flat_sheet and rows, cols > 0: the dots on a rows x cols grid of `spacing_m` instead of at
  // random (num_dots is ignored: rows * cols dots), centred where the cameras look, dot (row, col) with
  // id row * cols + col as tracking/grid_identity.h names a modified circle grid seen from its printed
  // side (+col, +row and the face towards the cameras a right-handed frame); the origin dot 0 is drawn
  // origin_radius_scale times larger (SimTruth::dot_radius_scale), the grid's orientation marker. The
  // yardstick is then dots 0 and rows * cols - 1 (the diagonal). Fails when the grid does not fit in
  // every view.
  struct SheetGrid {
    int rows = 0;
    int cols = 0;
    double spacing_m = 0.015;
    double origin_radius_scale = 1.6;  // area x 2.56: above grid_identity's min_origin_area_ratio of 2
  };
  SheetGrid sheet_grid;
  bool HasSheetGrid() const { return flat_sheet && sheet_grid.rows > 0 && sheet_grid.cols > 0; }
  // Rendered sessions: the dots are discs of this radius (m), and in every view the rims of any two
  // projected discs (radius fx * r / depth) stay at least min_rim_gap_diameters of the larger projected
  // diameter apart, so that a blob detector and a tracker can keep them apart (0 = no spacing rule,
  // the point-projection default). Dots that break it are redrawn, so it changes the scene.
  double separation_dot_radius_m = 0;
  double min_rim_gap_diameters = 0.5;
  double pixel_noise_px = 0.2;      // Gaussian, std per coordinate (the paper's Table 1, read as a std)
  // Gaussian, std per joint: the recorded joint readings are the true angles plus this noise (the images
  // are taken at the true angles). Drawn from its own stream (noise_seed), so the pixel noise is the same at
  // any level. 0: readings exact.
  double joint_noise_rad = 0;
  int num_identification_poses = 15;  // the first ones; the rest are verification poses
  // Eye-to-hand only (in place of num_dots and yardstick_length_m): num_dots dots on a square plate of side
  // 2 half_size_m whose face is the plane z = standoff_m of the flange frame (facing along the flange's z
  // axis), every raised_every-th dot raised_m above the face (not coplanar). The yardstick's two ends,
  // yardstick_length_m apart, lie on the face.
  struct Plate {
    int num_dots = 16;
    double yardstick_length_m = 0.12;
    double half_size_m = 0.08;
    double standoff_m = 0.03;
    double raised_m = 0.025;
    int raised_every = 4;
  };
  Plate plate;
  std::string Validate() const;
};

struct SimTruth {
  RobotModel nominal;                       // what the solver is given
  Eigen::VectorXd rho_true;                 // hidden, in the nominal model's parameterisation
  std::vector<int> perturbed_indices;       // which entries of rho carry hidden errors
  CameraIntrinsics camera_true;             // hidden f_x
  // In the points' frame: the base (eye-in-hand), the flange (eye-to-hand). dot id = index.
  std::vector<Eigen::Vector3d> dots_in_base;
  // True camera pose per pose in the points' frame: PointsFromCam(nominal, rho_true, q) (= BaseFromCam in
  // eye-in-hand; the fixed camera in eye-to-hand is FixedCameraTruth).
  std::vector<Rigid3> base_from_cam;
  std::vector<double> dot_radius_scale;     // per dot, of the rendered radius; empty: 1 for every dot
};

struct SimResult {
  bool ok = false;
  std::string message;
  ObservationSet observations;
  SimTruth truth;
};

// Eye-to-hand: the true fixed camera in the base frame, BaseFromCam(nominal, rho_true, any joints).
Rigid3 FixedCameraTruth(const SimTruth& truth);

// The nominal fixed camera of a simulated eye-to-hand cell for `robot` (its DH and home_joints_rad, the
// pose the arm rests in): distance_m in front of the flange along its z axis at home, looking back at the
// flange, its x axis along the flange's x: the plate faces the camera at home, whatever the arm. Every
// command that builds the simulated eye-to-hand cell (plan, run, simulate) takes this camera, so that a
// plan and the session run on it agree.
Rigid3 DefaultFixedCamera(const RobotModel& robot, const Eigen::VectorXd& home_joints_rad, double distance_m = 0.8);

// Simulates a session on `trajectory` (joint angles, rad). Fails (ok = false, message) if the trajectory
// leaves the joint limits or no scene of num_dots dots fits in every view.
SimResult Simulate(const RobotModel& nominal, const std::vector<Eigen::VectorXd>& trajectory,
                   const SimOptions& options);

// Re-draws only the pixel noise of an existing simulation (same world, new noise_seed / level).
ObservationSet Reobserve(const SimResult& world, double pixel_noise_px, uint64_t noise_seed);

// The check distances used to score verification: pairs (i, i + n/2) of the scene, known lengths.
std::vector<KnownDistance> CheckPairs(const std::vector<Eigen::Vector3d>& dots_in_base);

}  // namespace selfcal::sim
