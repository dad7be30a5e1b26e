// What the operator sees of a pose: the frames shown to a live view (RunContext::observe) with their dots,
// and the frames of a skipped pose kept in images/rejected/ (session_runner.h).
#include "acquisition/session_runner_internal.h"
#include "base/crc32.h"
#include "capture/png_codec.h"

namespace selfcal::acquisition {

const char* FramePhaseName(FramePhase phase) {
  switch (phase) {
    case FramePhase::kMoving: return "moving";
    case FramePhase::kSettled: return "settled";
    case FramePhase::kAccepted: return "accepted";
    case FramePhase::kSkipped: return "skipped";
  }
  return "unknown";
}

namespace internal {

void Runner::StartPoseView() {
  pose_frames_.clear();
  lost_.clear();
  named_ids_.clear();
  candidates_.clear();
}

void Runner::Observe(const capture::Frame& frame, FramePhase phase, int pose, const std::string& detail) {
  if (!c_.observe) return;
  FrameView view;
  view.frame = &frame;
  view.phase = phase;
  view.pose = pose;
  view.pose_id = plan_[pose].id;
  view.num_poses = static_cast<int>(plan_.size());
  view.detail = detail;
  std::set<int> shown;
  for (const tracking::PreviousDot& d : tracked_) {
    const ViewDotState state = named_ids_.count(d.id) > 0 ? ViewDotState::kNamed : ViewDotState::kTracked;
    view.dots.push_back({d.id, d.centroid_px, state});
    shown.insert(d.id);
  }
  if (phase != FramePhase::kMoving) {
    for (const tracking::PreviousDot& d : candidates_) {
      if (shown.insert(d.id).second) view.dots.push_back({d.id, d.centroid_px, ViewDotState::kCandidate});
    }
  }
  for (const auto& [id, uv] : lost_) {
    if (shown.count(id) == 0) view.dots.push_back({id, uv, ViewDotState::kLost});
  }
  c_.observe(view);
}

std::vector<std::string> Runner::SaveRejectedFrames(int pose, const std::string& reason) {
  std::vector<std::string> images;
  for (const RejectedFrame& rejected : pose_frames_) {
    const capture::Frame& frame = rejected.frame;
    Result<std::string> png = capture::EncodeGreyPng(frame.image, o_.png_compression);
    const std::string name = plan_[pose].id + "_" + std::to_string(rejected_written_[pose]++) + ".png";
    const Status written = png.ok() ? c_.session->WriteRejectedImage(name, *png) : png.status();
    if (!written.ok()) {
      if (Fault("rejected_frame_not_saved", pose, written.message()) == Step::kEnd) break;
      continue;
    }
    const std::string image = session::RejectedImageRecordPath(name);
    if (!Record({{"type", "frame_rejected"}, {"pose", pose}, {"image", image}, {"crc32", Crc32Hex(Crc32(*png))},
                 {"bytes", png->size()}, {"exposure_time_s", frame.exposure_time_s}, {"sequence", frame.sequence},
                 {"reason", rejected.reason.empty() ? reason : rejected.reason}})) {
      break;
    }
    images.push_back(image);
  }
  return images;
}

}  // namespace internal
}  // namespace selfcal::acquisition
