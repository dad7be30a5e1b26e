#include "session/samples.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "base/atomic_file.h"
#include "base/crc32.h"
#include "session/file_util.h"

namespace selfcal::session {

namespace {

constexpr int kMaxPoses = 100000;
constexpr std::size_t kMaxJoints = 32;
constexpr std::size_t kMaxDots = 100000;

// A validation failure inside one record; ReadSessionLog turns it into a Status.
class RecordError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Typed access to the fields of one record, each failure naming record, type and field.
class Fields {
 public:
  Fields(const nlohmann::json& record, std::size_t index, std::string type)
      : record_(record), index_(index), type_(std::move(type)) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw RecordError(Where() + (field.empty() ? "" : ": field \"" + field + "\"") + ": " + what);
  }
  std::string Where() const { return "journal record " + std::to_string(index_ + 1) + " (" + type_ + ")"; }

  const nlohmann::json& Get(const std::string& key) const {
    const auto it = record_.find(key);
    if (it == record_.end()) Fail(key, "missing");
    return *it;
  }
  bool Has(const std::string& key) const { return record_.contains(key); }

  std::int64_t Integer(const std::string& key, std::int64_t min, std::int64_t max) const {
    return IntegerOf(Get(key), key, min, max);
  }
  std::int64_t IntegerOf(const nlohmann::json& value, const std::string& key, std::int64_t min,
                         std::int64_t max) const {
    if (!value.is_number_integer()) Fail(key, "expected an integer, found " + value.dump());
    if (value.is_number_unsigned() && value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
      Fail(key, value.dump() + " is larger than " + std::to_string(max));
    }
    const std::int64_t number = value.get<std::int64_t>();
    if (number < min || number > max) {
      Fail(key, std::to_string(number) + " is outside [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    return number;
  }
  double Number(const std::string& key) const { return NumberOf(Get(key), key); }
  double NumberOf(const nlohmann::json& value, const std::string& key) const {
    if (!value.is_number()) Fail(key, "expected a finite number, found " + value.dump());
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(key, "expected a finite number, found " + value.dump());
    return number;
  }
  std::string String(const std::string& key) const {
    const nlohmann::json& value = Get(key);
    if (!value.is_string() || value.get_ref<const std::string&>().empty()) {
      Fail(key, "expected a non-empty string, found " + value.dump());
    }
    return value.get<std::string>();
  }
  std::string OptionalString(const std::string& key) const {
    if (!Has(key)) return "";
    if (!Get(key).is_string()) Fail(key, "expected a string, found " + Get(key).dump());
    return Get(key).get<std::string>();
  }
  // An array of finite numbers; `size` 0: 1 .. kMaxJoints entries.
  std::vector<double> Joints(const std::string& key, std::size_t size) const {
    const nlohmann::json& value = Get(key);
    const bool size_ok = size == 0 ? value.size() >= 1 && value.size() <= kMaxJoints : value.size() == size;
    if (!value.is_array() || !size_ok) {
      Fail(key, "expected an array of " + (size == 0 ? "1-" + std::to_string(kMaxJoints) : std::to_string(size)) +
                    " finite numbers, found " +
                    (value.is_array() ? std::to_string(value.size()) + " values" : value.dump()));
    }
    std::vector<double> joints;
    for (const nlohmann::json& item : value) joints.push_back(NumberOf(item, key));
    return joints;
  }
  PoseRole Role() const {
    const std::string role = String("role");
    if (role == "identification") return PoseRole::kIdentification;
    if (role == "verification") return PoseRole::kVerification;
    Fail("role", "\"" + role + "\" is neither \"identification\" nor \"verification\"");
  }
  // The "image" field: "images/<name>", or with `rejected` "images/rejected/<name>".
  std::string Image(bool rejected = false) const { return ImagePath(String("image"), rejected, "image"); }
  std::string ImagePath(const std::string& image, bool rejected, const std::string& key) const {
    const std::string prefix =
        std::string(kImagesDirName) + "/" + (rejected ? std::string(kRejectedDirName) + "/" : "");
    if (image.compare(0, prefix.size(), prefix) != 0 || !internal::SafeFileName(image.substr(prefix.size()))) {
      Fail(key, "\"" + image + "\" is not \"" + prefix + "<plain file name>\"");
    }
    return image;
  }
  std::uint32_t Crc32() const {
    const std::string text = String("crc32");
    const bool hex = text.size() == 8 && std::all_of(text.begin(), text.end(), [](char c) {
                       return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
                     });
    if (!hex) Fail("crc32", "\"" + text + "\" is not 8 lower-case hex digits");
    return static_cast<std::uint32_t>(std::stoul(text, nullptr, 16));
  }

 private:
  const nlohmann::json& record_;
  std::size_t index_;
  std::string type_;
};

std::vector<SampleDot> ReadDots(const Fields& f, const std::string& name = "dots") {
  const nlohmann::json& value = f.Get(name);
  if (!value.is_array() || value.size() > kMaxDots) f.Fail(name, "expected an array of at most 100000 dots");
  std::vector<SampleDot> dots;
  std::set<int> ids;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const nlohmann::json& dot = value[i];
    const std::string key = name + "[" + std::to_string(i) + "]";
    if (!dot.is_object()) f.Fail(key, "expected an object");
    for (const char* field : {"id", "u", "v", "area", "w", "h"}) {
      if (!dot.contains(field)) f.Fail(key, std::string("missing \"") + field + "\"");
    }
    SampleDot d;
    d.id = static_cast<int>(f.IntegerOf(dot["id"], key + ".id", 0, 1 << 30));
    d.u_px = f.NumberOf(dot["u"], key + ".u");
    d.v_px = f.NumberOf(dot["v"], key + ".v");
    d.area_px2 = f.NumberOf(dot["area"], key + ".area");
    d.width_px = f.NumberOf(dot["w"], key + ".w");
    d.height_px = f.NumberOf(dot["h"], key + ".h");
    if (!ids.insert(d.id).second) f.Fail(key + ".id", "dot id " + std::to_string(d.id) + " repeats");
    dots.push_back(d);
  }
  return dots;
}

bool SamePlan(const PlannedPose& a, const PlannedPose& b) {
  return a.id == b.id && a.role == b.role && a.joints_rad.size() == b.joints_rad.size() &&
         a.joints_rad == b.joints_rad;
}

// The log being built, one record at a time.
class LogBuilder {
 public:
  void Add(const nlohmann::json& record, std::size_t index) {
    const auto type_it = record.find("type");
    if (type_it == record.end() || !type_it->is_string()) {
      throw RecordError("journal record " + std::to_string(index + 1) + ": no \"type\" string");
    }
    const std::string type = type_it->get<std::string>();
    const Fields f(record, index, type);
    if (index == 0 && type != "session_started") f.Fail("type", "a session journal starts with session_started");
    if (type == "session_started") {
      if (index != 0) f.Fail("type", "session_started appears again (a continued session writes resumed)");
      log_.started = true;
      log_.start_time_s = f.Number("time_s");
      log_.num_poses = static_cast<int>(f.Integer("num_poses", 0, kMaxPoses));
      log_.mode = f.String("mode");
    } else if (type == "resumed") {
      f.Number("time_s");
      ++log_.resumes;
      log_.finished = false;
    } else if (type == "pose_planned") {
      AddPlanned(f);
    } else if (type == "move_started") {
      const int pose = Pose(f);
      f.Number("time_s");
      f.Joints("from_rad", static_cast<std::size_t>(log_.plan[pose].joints_rad.size()));
    } else if (type == "move_done" || type == "settled") {
      Pose(f);
      f.Number("time_s");
    } else if (type == "frame_written") {
      AddFrame(f, index);
    } else if (type == "sample_accepted") {
      AddAccepted(f, index);
    } else if (type == "frame_rejected") {
      AddRejected(f, index);
    } else if (type == "dots_named_later") {
      AddNamedLater(f);
    } else if (type == "sample_skipped") {
      AddSkipped(f, index);
    } else if (type == "fault") {
      OptionalPose(f);
      f.OptionalString("detail");
      ++log_.faults_by_kind[f.String("kind")];
    } else if (type == "halted") {
      OptionalPose(f);
      f.OptionalString("detail");
      ++log_.halts_by_reason[f.String("reason")];
    } else if (type == "finished") {
      f.Number("time_s");
      log_.finished = true;
    } else {
      ++log_.unknown_records;
    }
  }

  SessionLog Take() { return std::move(log_); }

 private:
  // The pose a record names: in [0, num_poses) and planned.
  int Pose(const Fields& f) const {
    if (log_.num_poses == 0) f.Fail("pose", "the session has no poses");
    const int pose = static_cast<int>(f.Integer("pose", 0, log_.num_poses - 1));
    if (pose >= static_cast<int>(log_.plan.size())) {
      f.Fail("pose", "pose " + std::to_string(pose) + " is not planned (no earlier pose_planned record)");
    }
    return pose;
  }
  void OptionalPose(const Fields& f) const {
    if (f.Has("pose")) f.Integer("pose", 0, std::max(0, log_.num_poses - 1));
  }

  void AddPlanned(const Fields& f) {
    PlannedPose planned;
    if (log_.num_poses == 0) f.Fail("pose", "the session has no poses");
    const std::size_t pose = static_cast<std::size_t>(f.Integer("pose", 0, log_.num_poses - 1));
    planned.id = f.String("id");
    planned.role = f.Role();
    const std::vector<double> joints =
        f.Joints("joints_rad", log_.plan.empty() ? 0 : static_cast<std::size_t>(log_.plan[0].joints_rad.size()));
    planned.joints_rad = Eigen::Map<const Eigen::VectorXd>(joints.data(), static_cast<Eigen::Index>(joints.size()));
    const std::size_t next = log_.plan.size();
    if (pose < next) {
      if (!SamePlan(planned, log_.plan[pose])) f.Fail("pose", "planned again with other values");
      return;
    }
    if (pose != next) f.Fail("pose", "pose " + std::to_string(pose) + " planned before pose " + std::to_string(next));
    for (std::size_t other = 0; other < next; ++other) {
      if (log_.plan[other].id == planned.id) {
        f.Fail("id", "\"" + planned.id + "\" is the id of pose " + std::to_string(other));
      }
    }
    log_.plan.push_back(std::move(planned));
    log_.accepted.emplace_back();
    log_.skips.emplace_back();
  }

  void AddFrame(const Fields& f, std::size_t index) {
    FrameWritten frame;
    ReadFrame(f, index, /*rejected=*/false, &frame);
    Insert(f, frame, &log_.frames);
  }

  void AddRejected(const Fields& f, std::size_t index) {
    FrameRejected frame;
    ReadFrame(f, index, /*rejected=*/true, &frame);
    frame.reason = f.String("reason");
    Insert(f, frame, &log_.rejected);
  }

  // The fields frame_written and frame_rejected share.
  void ReadFrame(const Fields& f, std::size_t index, bool rejected, FrameWritten* frame) const {
    frame->pose = Pose(f);
    frame->image = f.Image(rejected);
    frame->crc32 = f.Crc32();
    frame->bytes = static_cast<std::uint64_t>(f.Integer("bytes", 0, std::int64_t{1} << 40));
    frame->exposure_time_s = f.Number("exposure_time_s");
    frame->sequence = f.Integer("sequence", 0, std::int64_t{1} << 62);
    frame->record = index;
  }

  // A repeat of an image's record must agree with the first.
  template <typename Frame>
  static void Insert(const Fields& f, const Frame& frame, std::map<std::string, Frame>* frames) {
    const auto [it, inserted] = frames->emplace(frame.image, frame);
    if (!inserted &&
        (it->second.pose != frame.pose || it->second.crc32 != frame.crc32 || it->second.bytes != frame.bytes)) {
      f.Fail("image", frame.image + " was recorded by record " + std::to_string(it->second.record + 1) +
                          " with another pose, size or CRC");
    }
  }

  void AddSkipped(const Fields& f, std::size_t index) {
    const int pose = Pose(f);
    SkippedSample skip{f.String("reason"), f.OptionalString("detail"), {}, index};
    if (f.Has("rejected_images")) {
      const nlohmann::json& list = f.Get("rejected_images");
      if (!list.is_array() || list.size() > 1000) f.Fail("rejected_images", "expected an array of at most 1000 images");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string key = "rejected_images[" + std::to_string(i) + "]";
        if (!list[i].is_string()) f.Fail(key, "expected a string");
        const std::string image = f.ImagePath(list[i].get<std::string>(), /*rejected=*/true, key);
        const auto frame = log_.rejected.find(image);
        if (frame == log_.rejected.end() || frame->second.pose != pose) {
          f.Fail(key, image + " has no earlier frame_rejected record of pose " + std::to_string(pose));
        }
        skip.rejected_images.push_back(image);
      }
    }
    ++log_.skips_by_reason[skip.reason];
    log_.skips[pose].push_back(std::move(skip));
  }

  void AddAccepted(const Fields& f, std::size_t index) {
    AcceptedSample sample;
    sample.pose = Pose(f);
    const PlannedPose& planned = log_.plan[sample.pose];
    sample.id = f.String("id");
    if (sample.id != planned.id)
      f.Fail("id", "\"" + sample.id + "\" but pose " + std::to_string(sample.pose) + " was planned as \"" + planned.id +
                       "\"");
    sample.role = f.Role();
    if (sample.role != planned.role) {
      f.Fail("role",
             std::string(PoseRoleName(sample.role)) + " but the pose was planned as " + PoseRoleName(planned.role));
    }
    sample.joints_rad = f.Joints("joints_rad", static_cast<std::size_t>(planned.joints_rad.size()));
    sample.joint_time_s = f.Number("joint_time_s");
    sample.settle_time_s = f.Number("settle_time_s");
    sample.exposure_time_s = f.Number("exposure_time_s");
    sample.image = f.Image();
    const auto frame = log_.frames.find(sample.image);
    if (frame == log_.frames.end()) f.Fail("image", sample.image + " has no earlier frame_written record");
    if (frame->second.pose != sample.pose) {
      f.Fail("image", sample.image + " was written for pose " + std::to_string(frame->second.pose));
    }
    sample.dots = ReadDots(f);
    if (f.Has("candidates")) sample.candidates = ReadDots(f, "candidates");
    if (f.Has("sim_clock_s")) sample.sim_clock_s = f.Number("sim_clock_s");
    sample.record = index;
    if (log_.accepted[sample.pose]) {
      log_.duplicate_accepts.push_back(index);
      return;
    }
    log_.last_accepted_pose = sample.pose;
    log_.accepted[sample.pose] = std::move(sample);
  }

  // dots_named_later: dots of an accepted sample's frame named after it was recorded, appended to it.
  void AddNamedLater(const Fields& f) {
    const int pose = Pose(f);
    if (!log_.accepted[pose]) f.Fail("pose", "pose " + std::to_string(pose) + " has no earlier sample_accepted record");
    AcceptedSample& sample = *log_.accepted[pose];
    for (const SampleDot& d : ReadDots(f)) {
      for (const SampleDot& held : sample.dots) {
        if (held.id == d.id) f.Fail("dots", "dot " + std::to_string(d.id) + " is already in the sample of pose " + std::to_string(pose));
      }
      sample.dots.push_back(d);
      ++sample.named_later;
    }
  }

  SessionLog log_;
};

}  // namespace


bool IsFinalSkipReason(const std::string& reason) {
  static const std::set<std::string> kFinal = {"move_failed", "not_settled", "bad_reading",
                                               "no_frame",    "bad_frame",   "too_few_dots",
                                               "moved_after_settle"};
  return kFinal.count(reason) > 0;
}

bool IsRevisitableSkipReason(const std::string& reason) {
  static const std::set<std::string> kRevisitable = {"too_few_dots", "not_settled", "bad_frame", "bad_reading",
                                                     "moved_after_settle"};
  return kRevisitable.count(reason) > 0;
}

bool SessionLog::PoseDone(int pose, int max_revisits) const {
  if (pose < 0 || pose >= static_cast<int>(plan.size())) return false;
  if (accepted[pose]) return true;
  int final_skips = 0;
  for (const SkippedSample& skip : skips[pose]) {
    if (!IsFinalSkipReason(skip.reason)) continue;
    if (!IsRevisitableSkipReason(skip.reason)) return true;
    ++final_skips;
  }
  return final_skips > std::max(0, max_revisits);
}

int SessionLog::FirstPoseWithoutAcceptedSample(int max_revisits) const {
  for (int pose = 0; pose < num_poses; ++pose) {
    if (!PoseDone(pose, max_revisits)) return pose;
  }
  return num_poses;
}

std::vector<int> SessionLog::PosesToVisit(int max_revisits) const {
  std::vector<int> poses;
  for (int pose = 0; pose < num_poses; ++pose) {
    if (!PoseDone(pose, max_revisits)) poses.push_back(pose);
  }
  return poses;
}

int SessionLog::SkippedThenAccepted() const {
  int n = 0;
  for (std::size_t pose = 0; pose < accepted.size(); ++pose) n += accepted[pose] && !skips[pose].empty() ? 1 : 0;
  return n;
}

int SessionLog::NumAccepted() const {
  return static_cast<int>(std::count_if(accepted.begin(), accepted.end(), [](const auto& s) { return s.has_value(); }));
}

const AcceptedSample* SessionLog::LastAcceptedSample() const {
  return last_accepted_pose ? &*accepted[*last_accepted_pose] : nullptr;
}

Result<SessionLog> ReadSessionLog(const std::vector<nlohmann::json>& records) {
  LogBuilder builder;
  try {
    for (std::size_t i = 0; i < records.size(); ++i) builder.Add(records[i], i);
  } catch (const RecordError& error) {
    return Status::Error(ErrorCode::kInvalidInput, error.what());
  } catch (const nlohmann::json::exception& error) {  // a value outside its type's range
    return Status::Error(ErrorCode::kInvalidInput, std::string("journal: ") + error.what());
  }
  return builder.Take();
}

namespace {

// The problems of one accepted sample's dots and joints, each a phrase naming the value.
void SampleContentProblems(const AcceptedSample& sample, const CameraIntrinsics& camera, const RobotModel& robot,
                           std::vector<std::string>* problems) {
  const double width = camera.width_px, height = camera.height_px;
  const auto outside = [](double x, double size) { return !(x >= -0.5 && x <= size - 0.5); };
  const auto bad_size = [](double x, double size) { return !(x > 0 && x <= size); };
  for (std::size_t i = 0; i < sample.dots.size(); ++i) {
    const SampleDot& d = sample.dots[i];
    std::ostringstream what;
    what.precision(9);
    what << "dots[" << i << "] (dot " << d.id << "): ";
    const std::size_t prefix = what.str().size();
    if (outside(d.u_px, width) || outside(d.v_px, height)) {
      what << "centre (" << d.u_px << ", " << d.v_px << ") px lies outside the " << camera.width_px << "x"
           << camera.height_px << " image";
    } else if (bad_size(d.width_px, width) || bad_size(d.height_px, height) || !(d.area_px2 > 0) ||
               d.area_px2 > width * height) {
      what << "size " << d.width_px << " x " << d.height_px << " px, area " << d.area_px2
           << " px^2 is not a dot of the image";
    }
    if (what.str().size() > prefix) problems->push_back(what.str());
  }
  if (sample.joints_rad.size() != robot.limits.size()) {
    problems->push_back(std::to_string(sample.joints_rad.size()) + " joint values, the robot has " +
                        std::to_string(robot.limits.size()));
    return;
  }
  for (std::size_t j = 0; j < sample.joints_rad.size(); ++j) {
    const double q = sample.joints_rad[j];
    if (q >= robot.limits[j].min_rad - 1e-9 && q <= robot.limits[j].max_rad + 1e-9) continue;
    std::ostringstream what;
    what.precision(9);
    what << "joint " << j + 1 << " = " << q << " rad lies outside its limits [" << robot.limits[j].min_rad << ", "
         << robot.limits[j].max_rad << "] rad";
    problems->push_back(what.str());
  }
}

}  // namespace

Status CheckSampleContents(const SessionLog& log, const std::string& journal_path, const CameraIntrinsics& camera,
                           const RobotModel& robot) {
  std::vector<std::string> problems;
  for (const std::optional<AcceptedSample>& sample : log.accepted) {
    if (!sample) continue;
    std::vector<std::string> found;
    SampleContentProblems(*sample, camera, robot, &found);
    for (const std::string& what : found) {
      problems.push_back(journal_path + ":" + std::to_string(sample->record + 1) + " (sample_accepted of pose " +
                         sample->id + "): " + what);
    }
  }
  if (problems.empty()) return Status::Ok();
  std::string message = "journal records refused (" + std::to_string(problems.size()) + " problems):";
  constexpr std::size_t kShown = 10;
  for (std::size_t i = 0; i < problems.size() && i < kShown; ++i) message += "\n  " + problems[i];
  if (problems.size() > kShown) message += "\n  ... and " + std::to_string(problems.size() - kShown) + " more";
  return Status::Error(ErrorCode::kInvalidInput, message);
}

Status VerifySampleImages(const std::string& session_path, const SessionLog& log) {
  std::vector<std::string> problems;
  for (const auto& sample : log.accepted) {
    if (!sample) continue;
    const FrameWritten& frame = log.frames.at(sample->image);
    const std::string where = sample->image + " (pose " + std::to_string(sample->pose) + ")";
    bool missing = false;
    Result<std::string> bytes = ReadFileCapped(internal::Join(session_path, sample->image), frame.bytes, &missing);
    if (!bytes.ok()) {
      problems.push_back(where + (missing ? ": missing" : ": " + bytes.status().message()));
    } else if (bytes->size() != frame.bytes) {
      problems.push_back(where + ": " + std::to_string(bytes->size()) + " bytes, the journal recorded " +
                         std::to_string(frame.bytes));
    } else if (Crc32(*bytes) != frame.crc32) {
      problems.push_back(where + ": CRC-32 " + Crc32Hex(Crc32(*bytes)) +
                         ", the journal recorded " + Crc32Hex(frame.crc32));
    }
  }
  if (problems.empty()) return Status::Ok();
  std::string message = "session " + session_path + ": images of accepted samples do not match the journal: ";
  for (std::size_t i = 0; i < problems.size(); ++i) message += (i ? "; " : "") + problems[i];
  return Status::Error(ErrorCode::kInvalidInput, message);
}

}  // namespace selfcal::session
