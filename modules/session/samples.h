// Reading a session's journal (docs/session-format.md, "Record types") into what the solver and the
// resume logic need: the plan, the accepted sample of each pose, the skips, faults and halts counted by
// reason, and the pose to resume from (../shared/RELIABILITY.md P3).
//
// Units: times in s on the session clock (robot/clock.h), joints in rad, pixels in px.
//
// Validation is strict for the record types below (types, array sizes, finite numbers, pose indices,
// consistency with the plan) and every error names the record (counted from 1, as Journal messages do),
// its type and the field; record types this version does not know are counted and otherwise ignored, so
// that a newer writer's additions do not make a session unreadable.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/status.h"
#include "observations/observation_set.h"
#include "session/planned_pose.h"
#include "session/session_dir.h"

namespace selfcal::session {

// The roles of observations/observation_set.h ("identification", "verification").
using selfcal::PoseRole;
using selfcal::PoseRoleName;

// pose_planned: PlannedPose (session/planned_pose.h); its index in SessionLog::plan is its pose.

// One dot of an accepted sample ("dots": [{"id", "u", "v", "area", "w", "h"}]).
struct SampleDot {
  int id = 0;
  double u_px = 0, v_px = 0;  // centre
  double area_px2 = 0;
  double width_px = 0, height_px = 0;  // bounding box
};

// frame_written.
struct FrameWritten {
  int pose = 0;
  std::string image;  // "images/<name>"
  std::uint32_t crc32 = 0;
  std::uint64_t bytes = 0;
  double exposure_time_s = 0;
  std::int64_t sequence = 0;
  std::size_t record = 0;  // index into the journal's records (0-based)
};

// sample_accepted.
struct AcceptedSample {
  int pose = 0;
  std::string id;
  PoseRole role = PoseRole::kIdentification;
  std::vector<double> joints_rad;
  double joint_time_s = 0;
  double settle_time_s = 0;
  double exposure_time_s = 0;
  std::string image;  // "images/<name>", named by an earlier frame_written of the same pose
  std::vector<SampleDot> dots;
  // Detections the session could pin to a dot only up to its epipolar segment (a dot seen once): never
  // observations, only a second ray that the next pose's prediction confirms or forgets (optional).
  std::vector<SampleDot> candidates;
  // How many of `dots` were appended by dots_named_later records: named in the sample's frame after it
  // was recorded, from the predictions of the session's other samples (acquisition/late_naming.h).
  int named_later = 0;
  std::optional<double> sim_clock_s;
  std::size_t record = 0;
};

// frame_rejected: a frame grabbed at a pose that was then skipped, kept for the operator in
// images/rejected/ (never an observation; readers that solve ignore it): the fields of frame_written
// (image: "images/rejected/<name>") and why the frame was not recorded.
struct FrameRejected : FrameWritten {
  std::string reason;  // the pose's skip reason, or e.g. "stale_frame"
};

// sample_skipped.
struct SkippedSample {
  std::string reason;  // e.g. "move_failed", "too_few_dots"
  std::string detail;
  // The frames rejected at the pose before this skip ("images/rejected/<name>", each named by an
  // earlier frame_rejected record of the same pose); optional, empty when no frame was grabbed.
  std::vector<std::string> rejected_images;
  std::size_t record = 0;
};

// Whether a skip reason closes its pose: move_failed, not_settled, bad_reading, no_frame, bad_frame,
// too_few_dots, moved_after_settle. A pose skipped for another reason (e.g. an interruption) is visited again on resume; a
// halt is not a skip.
bool IsFinalSkipReason(const std::string& reason);

// Whether a final skip reason may be retried by a resumed session (`selfcal run --resume
// --revisit-skipped N`): too_few_dots (a fault such as a jog can lose the dots for a few poses),
// not_settled, bad_frame, bad_reading and moved_after_settle (transient: the arm was moved between settle
// and capture). move_failed and no_frame are not retried.
bool IsRevisitableSkipReason(const std::string& reason);

struct SessionLog {
  bool started = false;  // the journal has its session_started record (an empty journal has not)
  int num_poses = 0;
  std::string mode;  // e.g. "simulated"
  double start_time_s = 0;
  int resumes = 0;        // resumed records
  bool finished = false;  // a finished record after the last session_started or resumed

  std::vector<PlannedPose> plan;                        // index = pose; poses 0 .. plan.size() - 1
  std::vector<std::optional<AcceptedSample>> accepted;  // per planned pose: its first accepted sample
  std::vector<std::vector<SkippedSample>> skips;        // per planned pose, in journal order
  std::map<std::string, FrameWritten> frames;           // by image ("images/<name>"): its frame_written
  std::map<std::string, FrameRejected> rejected;        // by image ("images/rejected/<name>"): frame_rejected
  std::vector<std::size_t> duplicate_accepts;           // records of later sample_accepted of an accepted pose
  std::map<std::string, int> skips_by_reason;
  std::map<std::string, int> faults_by_kind;
  std::map<std::string, int> halts_by_reason;
  std::size_t unknown_records = 0;        // records of types this version does not know
  std::optional<int> last_accepted_pose;  // pose of LastAcceptedSample()

  // Every pose of session_started has its pose_planned record.
  bool plan_complete() const { return static_cast<int>(plan.size()) == num_poses; }
  // The pose has an accepted sample or a final skip (IsFinalSkipReason). With `max_revisits` > 0, a pose
  // whose final skips all have revisitable reasons (IsRevisitableSkipReason) is done only once it was
  // skipped more than max_revisits times: a resume retries it at most max_revisits times in all.
  bool PoseDone(int pose, int max_revisits = 0) const;
  // The resume point: the first pose in [0, num_poses) that is not PoseDone (a pose not planned yet is
  // not done); num_poses when every pose is done.
  int FirstPoseWithoutAcceptedSample(int max_revisits = 0) const;
  // Every pose that is not PoseDone(pose, max_revisits), in plan order.
  std::vector<int> PosesToVisit(int max_revisits) const;
  // Skipped poses that a later sample_accepted took (a revisit): their skips stay in skips and
  // skips_by_reason (every skip record counts), and the pose counts as accepted.
  int SkippedThenAccepted() const;
  int NumAccepted() const;
  // The accepted sample appended last (journal order; duplicates ignored), for the tracker state on
  // resume; nullptr when there is none.
  const AcceptedSample* LastAcceptedSample() const;
};

// Reads the records of a session journal (Journal::records()). Rules beyond the per-field checks: a
// non-empty journal starts with session_started, which appears once; pose indices lie in
// [0, num_poses); a pose is planned (pose_planned) before any other record names it, and planned again
// only identically; move_started.from_rad and sample_accepted.joints_rad have the plan's joint count;
// sample_accepted repeats its pose's id and role and names an image an earlier frame_written of the same
// pose recorded; a second frame_written of an image must agree with the first; dot ids within a sample
// are distinct; frame_rejected names an image under images/rejected/ (a repeat must agree), and a
// sample_skipped's rejected_images name earlier frame_rejected records of its pose. A second sample_accepted of an accepted pose is kept out (the first counts) and listed in
// duplicate_accepts. A dots_named_later record names an accepted pose and dots not yet in its sample, which
// are appended to that sample's dots. kInvalidInput naming the record, its type and field.
Result<SessionLog> ReadSessionLog(const std::vector<nlohmann::json>& records);

// Checks what the per-field checks of ReadSessionLog cannot: the contents of every accepted sample against
// the session's camera and robot (a damaged or forged record whose CRC is valid): each dot's centre inside
// the `camera` image (u in [-0.5, width - 0.5], v likewise), its area, width and height > 0 and within the
// image, and the joints within the robot's limits (1e-9 rad, the session loop's own tolerance).
// kInvalidInput listing every problem, each naming the journal line (`journal_path`:N, N = the record
// counted from 1), the pose id and the value.
Status CheckSampleContents(const SessionLog& log, const std::string& journal_path, const CameraIntrinsics& camera,
                           const RobotModel& robot);

// Checks that the image of every accepted sample exists in the session directory `session_path` and has
// the size and CRC-32 its frame_written record gives (P2); reads only. kInvalidInput listing every missing or
// differing image.
Status VerifySampleImages(const std::string& session_path, const SessionLog& log);
inline Status VerifySampleImages(const Session& session, const SessionLog& log) {
  return VerifySampleImages(session.path(), log);
}

}  // namespace selfcal::session
