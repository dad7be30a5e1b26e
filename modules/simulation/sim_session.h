// Module simulation (ARCHITECTURE.md): the only module above sim that links it. This header (the cell;
// SimCellOptionsFor in sim_run_settings.h: the cell of a run.json, shared by `run` and the audit) and:
//   identity_audit.h, session_audit.h  AuditIdentities / AuditSession: a simulated session's dot identities
//                           scored against the hidden truth, the world rebuilt from the session's inputs and
//                           checked against its setup.json
//   rendered_observations.h ObserveRendered: observations from rendered images
//   bound_sweep.h           SweepTwoViewBound
//   study.h                 RunStudy: Table 2 / Fig. 6 Monte Carlo, both methods, the bundle's Cramer-Rao bound per
//                           parameter and for the 3-D error, coverage; flat dot sheets
//   detect_folder.h         WriteDetectFolder: the cell as a folder of images, poses and hidden truth, the input of
//                           `selfcal detect` (test/tools/selfcal_render_sequence --detect-folder)
// Uses calibration, acquisition, sim, tracking, kinematics, session; geometry, camera, io, base private.
//
// A simulated cell for sessions: the simulated world (hidden robot errors, hand-eye, f_x, spaced dots),
// a SimulatedRobot moving the true arm on a simulated clock, and the rendered SimulatedCamera looking
// through the true kinematics at the arm's true joints at every exposure, so that RunSession runs on it
// exactly as on hardware (issue 6; `selfcal simulate` and `selfcal run --backend sim --camera sim`).
//
// With any other robot (`selfcal run --backend network|manual|... --camera sim`, a rehearsal without a
// camera), FollowReportedJoints makes the same cell's camera follow that robot instead: each frame renders
// the cell's world at the joints the robot reports when the frame is delivered, in real time.
//
// The first frame's dots are named by TruthIdentifier (the renderer knows which disc is which), standing
// in for a pattern or AprilTags; every later identity comes from tracking alone.
//
// Restart model (resume after a kill): a simulated arm that was killed mid-session is rebuilt at rest at
// the target of the last accepted sample, with the clock at that sample's journaled time, which is what
// an uninterrupted run has at that moment once the ring-down has ended (ring_cutoff_s < settle dwell).
#pragma once

#include <memory>
#include <optional>

#include "acquisition/motion_safety.h"
#include "acquisition/session_runner.h"
#include "robot/simulated_robot.h"
#include "sim/simulated_camera.h"
#include "sim/sim_world.h"

namespace selfcal::simulation {

// Names detections by the nearest projected disc of the camera's last render (within match_radius_px).
// `marked_ids` (the yardstick's ends) are the dots a real scene marks with a tag: FindMarked names them in
// any frame; every other id after the first frame comes from tracking alone.
class TruthIdentifier : public acquisition::DotIdentifier {
 public:
  TruthIdentifier(const sim::SimulatedCamera* camera, std::vector<int> marked_ids, double match_radius_px = 3.0)
      : camera_(camera), marked_ids_(std::move(marked_ids)), match_radius_px_(match_radius_px) {}
  Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                      const tracking::DetectionReport& detections) override;
  std::vector<tracking::PreviousDot> FindMarked(const capture::Frame& frame,
                                                const tracking::DetectionReport& detections,
                                                const std::vector<int>& missing_ids) override;
  std::vector<int> MarkedIds() const override { return marked_ids_; }

 private:
  // The detections that name a rendered dot among `ids` (all when empty): sim::NameByNearestDisc.
  std::vector<tracking::PreviousDot> Name(const tracking::DetectionReport& detections,
                                          const std::vector<int>& ids) const;
  const sim::SimulatedCamera* camera_;
  std::vector<int> marked_ids_;
  double match_radius_px_;
};

struct SimCellOptions {
  sim::SimOptions world;                 // seeds, hidden errors, camera; spacing is switched on here
  sim::SimulatedCameraOptions camera;    // rendering, frame period
  double max_velocity_rad_s = 1.0471975511965976;  // 60 deg/s on every joint
  robot::SimulatedRobotFaults faults;
  double ring_cutoff_s = 0.5;            // the ring-down ends exactly this long after arrival
};

// Everything a simulated session needs, owned together (the robot refers to the clock, the camera's
// pose function to the robot).
struct SimCell {
  std::unique_ptr<sim::SimResult> world;  // heap: the camera's pose function points into it
  std::unique_ptr<robot::SimulatedClock> clock;
  std::unique_ptr<robot::SimulatedRobot> robot;
  std::unique_ptr<sim::SimulatedCamera> camera;
  std::unique_ptr<TruthIdentifier> identifier;
};

// Builds the cell for `plan` on the nominal robot. `start_joints_rad` / `start_time_s`: where the arm
// rests and the clock starts (a fresh session: the plan's first pose at t = 0; a resumed one: see the
// header comment). Fails (kDegenerateData) when the world cannot be simulated.
Result<SimCell> MakeSimCell(const RobotModel& nominal, const std::vector<acquisition::PlannedPose>& plan,
                            const SimCellOptions& options, const Eigen::VectorXd& start_joints_rad,
                            double start_time_s);

// Rebuilds the clock, arm, camera and identifier of `cell` on its world (no new simulation): the arm at
// rest at `start_joints_rad`, the clock at `start_time_s` (the restart model of the header comment).
void RestartSimCell(SimCell* cell, const SimCellOptions& options, const Eigen::VectorXd& start_joints_rad,
                    double start_time_s);

// --camera sim with a robot other than the cell's own: the cell's camera (same world, scene, true arm and
// rendering) is rebuilt in real time on the monotonic clock (the clock every live backend stamps its
// readings with), and each frame is rendered at the true arm's camera pose at the joints `robot` reports
// when the frame is delivered: one Robot::ReadJoints per frame (those readings count among the robot's).
// A reading that fails, is short or is not finite leaves the camera where the last good one put it (the
// session finds the bad reading itself at its next call); before any good reading, at `start_joints_rad`.
// The cell's own SimulatedRobot is removed (nothing may drive it). `robot` must outlive the camera.
void FollowReportedJoints(SimCell* cell, const SimCellOptions& options, robot::Robot* robot,
                          const Eigen::VectorXd& start_joints_rad);

// The setup of a simulated session: the world's observation header (camera with the nominal f_x,
// yardstick, check distances), no poses.
ObservationSet SimSetup(const SimCell& cell);

}  // namespace selfcal::simulation
