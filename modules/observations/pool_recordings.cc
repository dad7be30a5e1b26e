#include "observations/pool_recordings.h"

namespace selfcal {

namespace {

// Empty when `other` can be calibrated with `first`; otherwise what differs, in words.
std::string Difference(const ObservationSet& first, const ObservationSet& other) {
  if (first.UsesFlangePoses() != other.UsesFlangePoses()) {
    return first.UsesFlangePoses() ? "it has joint angles, the first recording flange poses"
                                   : "it has flange poses, the first recording joint angles";
  }
  if (other.robot.num_joints() != first.robot.num_joints()) {
    return "its robot has " + std::to_string(other.robot.num_joints()) + " joints, the first recording's " +
           std::to_string(first.robot.num_joints());
  }
  const auto same = [](const Rigid3& a, const Rigid3& b) { return a.rotation == b.rotation && a.translation == b.translation; };
  if (KinematicParameters::Nominal(other.robot) != KinematicParameters::Nominal(first.robot) ||
      !same(other.robot.base_from_link0, first.robot.base_from_link0) ||
      !same(other.robot.link_n_from_flange, first.robot.link_n_from_flange)) {
    return "its robot description differs from the first recording's (one arm, one description)";
  }
  if (other.camera.width_px != first.camera.width_px || other.camera.height_px != first.camera.height_px) {
    return "its images are " + std::to_string(other.camera.width_px) + " x " + std::to_string(other.camera.height_px) +
           " px, the first recording's " + std::to_string(first.camera.width_px) + " x " +
           std::to_string(first.camera.height_px) + " (one camera)";
  }
  return "";
}

}  // namespace

Result<ObservationSet> PoolRecordings(const std::vector<Recording>& recordings) {
  if (recordings.empty()) return Status::Error(ErrorCode::kInvalidInput, "no recording to pool");
  ObservationSet pooled = recordings.front().observations;
  pooled.poses.clear();
  for (const Recording& r : recordings) {
    if (r.label.empty()) return Status::Error(ErrorCode::kInvalidInput, "a recording without a name cannot be a scene");
    if (const std::string d = Difference(recordings.front().observations, r.observations); !d.empty()) {
      return Status::Error(ErrorCode::kInvalidInput, "recording `" + r.label + "` cannot be calibrated with `" +
                                                         recordings.front().label + "`: " + d);
    }
    for (PoseObservation pose : r.observations.poses) {
      pose.id = r.label + "/" + pose.id;
      pose.scene = pose.scene.empty() ? r.label : r.label + "/" + pose.scene;
      pooled.poses.push_back(std::move(pose));
    }
  }
  return pooled;
}

}  // namespace selfcal
