#include "urdf/urdf_calibrated.h"

#include <regex>
#include <vector>

#include <urdf_model/model.h>

#include "base/atomic_file.h"
#include "urdf/urdf_chain.h"
#include "urdf/urdf_parse.h"
#include "urdf/urdf_writer.h"

namespace selfcal::urdf {
namespace {

// [begin, end) of every comment of `text`.
std::vector<std::pair<size_t, size_t>> Comments(const std::string& text) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t at = text.find("<!--"); at != std::string::npos; at = text.find("<!--", at)) {
    const size_t end = text.find("-->", at + 4);
    out.emplace_back(at, end == std::string::npos ? text.size() : end + 3);
    at = out.back().second;
  }
  return out;
}

bool InComment(const std::vector<std::pair<size_t, size_t>>& comments, size_t at) {
  for (const auto& [begin, end] : comments) {
    if (at >= begin && at < end) return true;
  }
  return false;
}

// The end (one past '>') of the tag starting at `at`, quotes respected; npos when unclosed.
size_t TagEnd(const std::string& text, size_t at) {
  char quote = 0;
  for (size_t i = at; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      return i + 1;
    }
  }
  return std::string::npos;
}

std::string Attribute(const std::string& tag, const std::string& key) {
  const std::regex pattern("\\s" + key + "\\s*=\\s*(\"([^\"]*)\"|'([^']*)')");
  std::smatch match;
  if (!std::regex_search(tag, match, pattern)) return "";
  return match[2].matched ? match[2].str() : match[3].str();
}

// Where `<name` opens a tag (followed by a space, '/' or '>') at or after `from` and before `to`, outside comments.
size_t FindTag(const std::string& text, const std::string& tag, size_t from, size_t to,
               const std::vector<std::pair<size_t, size_t>>& comments) {
  for (size_t at = text.find("<" + tag, from); at != std::string::npos && at < to; at = text.find("<" + tag, at + 1)) {
    const size_t after = at + 1 + tag.size();
    if (after < text.size() && (std::isspace(static_cast<unsigned char>(text[after])) || text[after] == '/' ||
                                text[after] == '>') &&
        !InComment(comments, at)) {
      return at;
    }
  }
  return std::string::npos;
}

}  // namespace

Result<std::string> ReplaceJointOrigins(const std::string& text, const std::string& name,
                                        const std::map<std::string, Rigid3>& origins) {
  std::string out = text;
  for (const auto& [joint, origin] : origins) {
    const auto comments = Comments(out);
    size_t start = std::string::npos, start_end = 0;
    for (size_t at = FindTag(out, "joint", 0, out.size(), comments); at != std::string::npos;
         at = FindTag(out, "joint", at + 1, out.size(), comments)) {
      const size_t end = TagEnd(out, at);
      if (end == std::string::npos) break;
      const std::string tag = out.substr(at, end - at);
      if (Attribute(tag, "name") == joint && !Attribute(tag, "type").empty()) {
        start = at;
        start_end = end;
        break;
      }
    }
    if (start == std::string::npos) {
      return Status::Error(ErrorCode::kInvalidInput, name + ": no <joint> named `" + joint + "` found in the text");
    }
    const size_t close = out.find("</joint>", start_end);
    const size_t origin_at = FindTag(out, "origin", start_end, close, comments);
    std::string element = OriginElement(origin);
    if (origin_at == std::string::npos) {
      const size_t line = out.rfind('\n', start);
      const std::string indent = out.substr(line + 1, start - line - 1);
      out.insert(start_end, "\n" + indent + "  " + element);
      continue;
    }
    const size_t origin_end = TagEnd(out, origin_at);
    if (origin_end == std::string::npos) return Status::Error(ErrorCode::kInvalidInput, name + ": unclosed <origin>");
    if (out.compare(origin_end - 2, 2, "/>") != 0) element.replace(element.size() - 2, 2, ">");  // <origin ...></origin>
    out.replace(origin_at, origin_end - origin_at, element);
  }
  return out;
}

Result<std::string> CalibratedUserUrdf(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                                       const RobotModel& calibrated, const FkCheckOptions& check) {
  Result<std::shared_ptr<::urdf::ModelInterface>> parsed = ParseUrdfText(text, name);
  if (!parsed.ok()) return parsed.status();
  Result<UrdfRobot> nominal = ParseUrdfRobot(text, name, spec, calibrated.flange_from_cam, check);
  if (!nominal.ok()) return nominal.status();
  const RobotModel& model = nominal->model;
  if (model.num_joints() != calibrated.num_joints()) {
    return Status::Error(ErrorCode::kInvalidInput, name + ": its chain has " + std::to_string(model.num_joints()) +
                                                       " joints, the calibrated model " +
                                                       std::to_string(calibrated.num_joints()));
  }
  std::string error;
  const auto joints = JointsBetween(**parsed, spec.base_link, spec.tip_link, &error);
  if (!error.empty()) return Status::Error(ErrorCode::kInvalidInput, name + ": " + error);
  std::map<std::string, Rigid3> origins;
  Rigid3 old_pose, new_pose;  // base_from_link at q = 0 of the current joint's parent: input, calibrated
  Rigid3 nominal_m = model.base_from_link0, calibrated_m = calibrated.base_from_link0;
  int i = 0;
  for (const auto& joint : joints) {
    const Rigid3 origin = RigidOf(joint->parent_to_joint_origin_transform);
    const Rigid3 old_child = old_pose * origin;
    if (joint->type == ::urdf::Joint::FIXED) {
      old_pose = old_child;
      new_pose = new_pose * origin;
      continue;
    }
    const LinkParameters& n = model.links[i];
    const LinkParameters& c = calibrated.links[i];
    nominal_m = nominal_m * LinkTransform<double>(n.alpha, n.a, n.beta, n.theta, n.d);
    calibrated_m = calibrated_m * LinkTransform<double>(c.alpha, c.a, c.beta, c.theta, c.d);
    const Rigid3 child_from_m = old_child.Inverse() * nominal_m;  // X_i
    const Rigid3 new_child = calibrated_m * child_from_m.Inverse();
    origins[joint->name] = new_pose.Inverse() * new_child;
    old_pose = old_child;
    new_pose = new_child;
    ++i;
  }
  if (!spec.camera_link.empty()) {
    const auto camera_joints = JointsBetween(**parsed, spec.tip_link, spec.camera_link, &error);
    if (!error.empty() || camera_joints.empty()) {
      return Status::Error(ErrorCode::kInvalidInput, name + ": camera_link `" + spec.camera_link + "` below `" +
                                                         spec.tip_link + "`: " + error);
    }
    Rigid3 tip_from_parent;  // of the last joint, unchanged
    for (size_t k = 0; k + 1 < camera_joints.size(); ++k) {
      tip_from_parent = tip_from_parent * RigidOf(camera_joints[k]->parent_to_joint_origin_transform);
    }
    origins[camera_joints.back()->name] = tip_from_parent.Inverse() * calibrated.flange_from_cam;
  }
  Result<std::string> edited = ReplaceJointOrigins(text, name, origins);
  if (!edited.ok()) return edited;
  Result<FkCheck> compared = CompareWithKdl(*edited, name + " with the calibrated origins", spec, calibrated, check);
  if (!compared.ok()) return compared.status();
  return edited;
}

Result<std::string> CalibratedUserUrdfFile(const std::string& path, const UrdfChainSpec& spec,
                                           const RobotModel& calibrated) {
  Result<std::string> text = ReadFileCapped(path, kMaxUrdfBytes);
  if (!text.ok()) return text.status();
  return CalibratedUserUrdf(*text, path, spec, calibrated);
}

}  // namespace selfcal::urdf
