// The simulated camera: a capture::FrameSource that renders the simulated world (image_renderer.h) at
// the camera's true pose, so that session code runs unchanged on the simulator and on a V4L2 camera.
//
// Clock. Frames are exposed on a fixed grid t_k = first_exposure_s + k * frame_period_s of the
// camera's clock; k is the frame's sequence number. Whoever moves the simulated robot calls
// SetPose(base_from_cam, time_s) when the camera arrives at a new pose (time on the same clock); a
// frame exposed at t shows the latest pose set at or before t. So a caller that asks for a frame before
// the move ended (not_before_s too early) really gets an image of the old pose: the stale-frame case
// (../shared/RELIABILITY.md V5) is reproduced, not hidden.
//
//  - Simulated time (real_time = false, the default): the clock is virtual; Grab returns at once the
//    first grid frame exposed at or after max(not_before_s, previous frame + period). timeout_s is not
//    used. Deterministic.
//  - Real time (real_time = true): the clock is capture::MonotonicNowS(); the frame exposed at t_k is
//    delivered at t_k + readout_s, and Grab sleeps until then, or returns kTimeout if that is later than
//    timeout_s from the call (after sleeping the timeout).
//
// Pixel noise differs per frame: the noise stream is seeded with (render.noise_seed, sequence).
// After each successful Grab, last_render() holds the truth of that frame (per-dot centres, flags).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "camera/camera.h"
#include "capture/frame_checks.h"
#include "capture/frame_source.h"
#include "geometry/rigid3.h"
#include "sim/image_renderer.h"

namespace selfcal::sim {

struct SimulatedCameraOptions {
  RenderOptions render;
  double frame_period_s = 1.0 / 30;
  double first_exposure_s = 0.0;  // t_0 of the grid (simulated time; real time uses the clock at Open)
  bool real_time = false;
  double readout_s = 0.010;  // real time: delay from exposure to delivery
  bool check_frames = true;  // capture::CheckFrame on each rendered frame (kBadFrame)
  capture::FrameCheckOptions checks;
  std::string Validate() const;
};

// Per-frame noise seed for `sequence`: what SimulatedCamera passes to RenderDots.
uint64_t FrameNoiseSeed(uint64_t noise_seed, int64_t sequence);

class SimulatedCamera : public capture::FrameSource {
 public:
  // `camera` is the true camera (its f_x and k1, not the user's prior).
  SimulatedCamera(CameraIntrinsics camera, DotScene scene, SimulatedCameraOptions options = SimulatedCameraOptions());

  // The camera is at `base_from_cam` from `time_s` on. Times must not decrease (SELFCAL_CHECK).
  void SetPose(const Rigid3& base_from_cam, double time_s);
  // Instead of SetPose: the camera's pose as a function of the exposure time (a simulated robot's true
  // motion through its true kinematics), so that frames grabbed during a move show the arm moving.
  void SetPoseFunction(std::function<Rigid3(double time_s)> base_from_cam_at);

  std::string Describe() const override;
  Status Open() override;
  Result<capture::Frame> Grab(double not_before_s, double timeout_s) override;
  void Close() override;

  // The camera's clock now: simulated time = the last frame's exposure (or first_exposure_s); real
  // time = MonotonicNowS().
  double Now() const;
  const RenderedImage& last_render() const { return last_render_; }
  const CameraIntrinsics& camera() const { return camera_; }
  const DotScene& scene() const { return scene_; }

 private:
  CameraIntrinsics camera_;
  DotScene scene_;
  SimulatedCameraOptions options_;
  std::vector<std::pair<double, Rigid3>> poses_;
  std::function<Rigid3(double)> pose_function_;  // (from time, base_from_cam), time non-decreasing
  bool open_ = false;
  double grid_origin_s_ = 0;
  int64_t last_sequence_ = -1;
  RenderedImage last_render_;
};

}  // namespace selfcal::sim
