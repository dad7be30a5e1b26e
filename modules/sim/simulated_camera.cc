#include "sim/simulated_camera.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>
#include <thread>

#include "base/status.h"

namespace selfcal::sim {

std::string SimulatedCameraOptions::Validate() const {
  std::ostringstream out;
  out << render.Validate();
  if (!std::isfinite(frame_period_s) || frame_period_s <= 0)
    out << "frame_period_s = " << frame_period_s << " must be > 0\n";
  if (!std::isfinite(first_exposure_s)) out << "first_exposure_s must be finite\n";
  if (!std::isfinite(readout_s) || readout_s < 0) out << "readout_s = " << readout_s << " must be >= 0\n";
  if (check_frames) out << checks.Validate();
  return out.str();
}

uint64_t FrameNoiseSeed(uint64_t noise_seed, int64_t sequence) {
  std::seed_seq seq{static_cast<uint32_t>(noise_seed), static_cast<uint32_t>(noise_seed >> 32),
                    static_cast<uint32_t>(sequence), static_cast<uint32_t>(static_cast<uint64_t>(sequence) >> 32)};
  uint32_t words[2];
  seq.generate(words, words + 2);
  return (uint64_t{words[0]} << 32) | words[1];
}

SimulatedCamera::SimulatedCamera(CameraIntrinsics camera, DotScene scene, SimulatedCameraOptions options)
    : camera_(std::move(camera)), scene_(std::move(scene)), options_(std::move(options)) {}

void SimulatedCamera::SetPose(const Rigid3& base_from_cam, double time_s) {
  SELFCAL_CHECK(std::isfinite(time_s), "pose time " << time_s);
  SELFCAL_CHECK(poses_.empty() || time_s >= poses_.back().first,
                "pose time " << time_s << " s is before the previous pose's " << poses_.back().first << " s");
  poses_.emplace_back(time_s, base_from_cam);
}

void SimulatedCamera::SetPoseFunction(std::function<Rigid3(double)> base_from_cam_at) {
  pose_function_ = std::move(base_from_cam_at);
}

std::string SimulatedCamera::Describe() const {
  std::ostringstream out;
  out << "simulated camera: " << camera_.width_px << "x" << camera_.height_px << " GREY8, f_x " << camera_.fx_px
      << " px, k1 " << camera_.k1 << ", " << scene_.centres_in_base.size() << " dots of radius "
      << 1000 * scene_.radius_m << " mm, " << 1000 * options_.frame_period_s << " ms/frame, "
      << (options_.real_time ? "real time" : "simulated time") << ", blur " << options_.render.blur_sigma_px
      << " px, noise " << options_.render.noise_std_grey << " grey";
  if (!open_) out << " (not open)";
  return out.str();
}

Status SimulatedCamera::Open() {
  if (const std::string problems = options_.Validate() + camera_.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "invalid simulated camera options:\n" + problems);
  }
  if (scene_.normals_in_base.size() != scene_.centres_in_base.size() || !(scene_.radius_m > 0)) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "invalid simulated scene: one normal per dot and a positive radius are needed");
  }
  grid_origin_s_ = options_.real_time ? capture::MonotonicNowS() : options_.first_exposure_s;
  last_sequence_ = -1;
  open_ = true;
  return Status::Ok();
}

void SimulatedCamera::Close() { open_ = false; }

double SimulatedCamera::Now() const {
  if (options_.real_time) return capture::MonotonicNowS();
  return last_sequence_ < 0 ? grid_origin_s_ : grid_origin_s_ + last_sequence_ * options_.frame_period_s;
}

Result<capture::Frame> SimulatedCamera::Grab(double not_before_s, double timeout_s) {
  if (!open_) return Status::Error(ErrorCode::kInvalidInput, "Grab on the simulated camera before Open");
  const double period = options_.frame_period_s;
  // First grid frame after the previous one, at or after not_before_s (and, in real time, not yet
  // exposed before this call: frames nobody grabbed are gone, as in a live camera).
  double earliest = std::isfinite(not_before_s) ? not_before_s : grid_origin_s_;
  const double call_time = options_.real_time ? capture::MonotonicNowS() : 0.0;
  if (options_.real_time) earliest = std::max(earliest, call_time - options_.readout_s);
  int64_t k = static_cast<int64_t>(std::ceil((earliest - grid_origin_s_) / period - 1e-9));
  k = std::max<int64_t>({k, last_sequence_ + 1, 0});
  const double exposure = grid_origin_s_ + k * period;

  if (options_.real_time) {
    const double deliver = exposure + options_.readout_s;
    const double deadline = call_time + std::max(0.0, timeout_s);
    if (deliver > deadline) {
      std::this_thread::sleep_for(std::chrono::duration<double>(std::max(0.0, deadline - capture::MonotonicNowS())));
      std::ostringstream why;
      why.precision(6);
      why << std::fixed << "simulated camera: no frame exposed at or after " << not_before_s << " s within "
          << timeout_s << " s (the next one is exposed at " << exposure << " s)";
      return capture::CaptureFailure(capture::CaptureError::kTimeout, why.str());
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(std::max(0.0, deliver - capture::MonotonicNowS())));
  }

  // The pose in effect at the exposure.
  Rigid3 base_from_cam;
  if (pose_function_) {
    base_from_cam = pose_function_(exposure);
  } else {
    const auto after = std::upper_bound(poses_.begin(), poses_.end(), exposure,
                                        [](double t, const std::pair<double, Rigid3>& p) { return t < p.first; });
    if (after == poses_.begin()) {
      std::ostringstream why;
      why.precision(6);
      why << std::fixed << "simulated camera: no pose at exposure time " << exposure
          << " s: SetPose must place the camera before frames are grabbed";
      return Status::Error(ErrorCode::kInvalidInput, why.str());
    }
    base_from_cam = std::prev(after)->second;
  }
  last_render_ =
      RenderDots(camera_, base_from_cam, scene_, options_.render, FrameNoiseSeed(options_.render.noise_seed, k));
  last_sequence_ = k;

  capture::Frame frame;
  frame.image = last_render_.image;
  frame.exposure_time_s = exposure;
  frame.sequence = k;
  frame.source = "sim";
  if (options_.check_frames) {
    if (Status s = capture::CheckFrame(frame.image, options_.checks, "simulated camera"); !s.ok()) return s;
  }
  return frame;
}

}  // namespace selfcal::sim
