// Renders a simulated session into a recorded-sequence folder (capture/recorded_sequence.h) plus a
// truth file, through the SimulatedCamera exactly as a session would grab it: the camera is placed at
// each pose (SetPose), and the frame is the first exposed settle_s after arrival. Replaying the folder
// with capture::RecordedSequence then exercises the same code path as a live camera.
//
// truth.yaml (format selfcal-sequence-truth, version 1) holds the world description, the true camera,
// the rendering options and, per frame (same order and image names as index.yaml): pose id and index,
// sequence number, exposure time, and per dot id: projected centre and exact area centroid (px, 4
// decimals), exact area (px^2), and the list of its flags among in_front, visible, fully_inside,
// clipped, overlapping, near_other (image_renderer.h). Tests exclude dots that are not Clean().
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "camera/camera.h"
#include "sim/image_renderer.h"
#include "sim/sim_world.h"

namespace selfcal::sim {

inline constexpr const char* kSequenceTruthName = "truth.yaml";

struct SequenceRenderOptions {
  std::string world_description;  // how to rebuild the world, for the truth file (free text)
  double dot_radius_m = kDefaultDotRadiusM;
  RenderOptions render;
  std::vector<int> pose_indices;  // poses of the world to render, in order; empty = all
  double frame_period_s = 1.0 / 30;
  double first_pose_time_s = 100.0;  // simulated clock: the camera reaches the first pose
  double pose_interval_s = 2.0;      // between arrivals at consecutive poses
  double settle_s = 0.5;             // the frame must be exposed this long after arrival
  int png_compression = 9;
  std::string Validate() const;
};

struct SequenceTruthDot {
  int id = -1;
  Eigen::Vector2d projected_centre_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d area_centroid_px = Eigen::Vector2d::Zero();
  double area_px2 = 0;
  bool in_front = false, visible = false, fully_inside = false, clipped = false, overlapping = false,
       near_other = false;
  bool Clean() const { return in_front && fully_inside && !overlapping && !near_other; }
};

struct SequenceTruthFrame {
  std::string image;
  std::string pose_id;
  int pose_index = -1;
  int64_t sequence = -1;
  double exposure_time_s = 0;
  std::vector<SequenceTruthDot> dots;  // by id
};

struct SequenceTruth {
  std::string world_description;
  CameraIntrinsics camera;
  double dot_radius_m = 0;
  RenderOptions render;
  std::vector<SequenceTruthFrame> frames;
};

// Renders the poses of `world` into the new folder `folder` (see capture::RecordedSequenceWriter::Create)
// and writes truth.yaml there. `truth` (optional) receives what was written, at full precision.
Status RenderSequenceFolder(const SimResult& world, const SequenceRenderOptions& options, const std::string& folder,
                            SequenceTruth* truth = nullptr);

// Reads a truth file written by RenderSequenceFolder (test and tool use; size-capped, every yaml-cpp
// error turned into a Status naming the file). ErrorCode::kInvalidInput.
Result<SequenceTruth> ReadSequenceTruth(const std::string& path);

}  // namespace selfcal::sim
