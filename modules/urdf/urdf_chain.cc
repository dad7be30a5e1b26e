#include "urdf/urdf_chain.h"

#include <algorithm>

#include <urdf_model/model.h>

namespace selfcal::urdf {
namespace {

const char* JointTypeName(int type) {
  switch (type) {
    case ::urdf::Joint::REVOLUTE:
      return "revolute";
    case ::urdf::Joint::CONTINUOUS:
      return "continuous";
    case ::urdf::Joint::PRISMATIC:
      return "prismatic";
    case ::urdf::Joint::FLOATING:
      return "floating";
    case ::urdf::Joint::PLANAR:
      return "planar";
    case ::urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

Status MissingLink(const ::urdf::ModelInterface& model, const std::string& file, const char* key,
                   const std::string& link) {
  std::string names;
  for (const auto& entry : model.links_) names += (names.empty() ? "" : ", ") + entry.first;
  return Status::Error(ErrorCode::kInvalidInput, file + ": " + key + " `" + link + "` is not a link of robot `" +
                                                     model.getName() + "` (links: " + names + ")");
}

}  // namespace

Rigid3 RigidOf(const ::urdf::Pose& pose) {
  const Eigen::Quaterniond q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  return Rigid3(q.normalized().toRotationMatrix(), Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z));
}

std::vector<::urdf::JointConstSharedPtr> JointsBetween(const ::urdf::ModelInterface& model, const std::string& top,
                                                       const std::string& bottom, std::string* error) {
  std::vector<::urdf::JointConstSharedPtr> joints;
  ::urdf::LinkConstSharedPtr link = model.getLink(bottom);
  while (link && link->name != top) {
    if (!link->parent_joint) {
      *error = "link `" + bottom + "` is not below link `" + top + "`";
      return {};
    }
    joints.push_back(link->parent_joint);
    link = model.getLink(link->parent_joint->parent_link_name);
  }
  std::reverse(joints.begin(), joints.end());
  return joints;
}


Result<UrdfChain> ExtractChain(const ::urdf::ModelInterface& model, const std::string& name,
                               const UrdfChainSpec& spec) {
  for (const auto& [key, link] : {std::pair<const char*, std::string>{"base_link", spec.base_link},
                                  {"tip_link", spec.tip_link},
                                  {"camera_link", spec.camera_link}}) {
    if (!link.empty() && !model.getLink(link)) return MissingLink(model, name, key, link);
  }
  std::string error;
  const std::vector<::urdf::JointConstSharedPtr> joints = JointsBetween(model, spec.base_link, spec.tip_link, &error);
  if (!error.empty()) return Status::Error(ErrorCode::kInvalidInput, name + ": " + error + " (base_link to tip_link)");
  UrdfChain chain;
  chain.robot_name = model.getName();
  Rigid3 base_from_link;
  for (const auto& joint : joints) {
    base_from_link = base_from_link * RigidOf(joint->parent_to_joint_origin_transform);
    if (joint->type == ::urdf::Joint::FIXED) continue;
    if (joint->type != ::urdf::Joint::REVOLUTE) {
      return Status::Error(ErrorCode::kInvalidInput,
                           name + ": joint `" + joint->name + "` is " + JointTypeName(joint->type) +
                               "; selfcal's model takes revolute joints with limits only (a continuous joint: give "
                               "it type=\"revolute\" and the <limit lower upper> the arm may travel)");
    }
    if (joint->mimic) {
      return Status::Error(ErrorCode::kInvalidInput, name + ": joint `" + joint->name + "` mimics `" +
                                                         joint->mimic->joint_name +
                                                         "`; mimic joints are not supported");
    }
    const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
    if (axis.norm() < 1e-9) {
      return Status::Error(ErrorCode::kInvalidInput, name + ": joint `" + joint->name + "` has a zero axis");
    }
    if (!joint->limits || !(joint->limits->lower < joint->limits->upper)) {
      return Status::Error(ErrorCode::kInvalidInput,
                           name + ": revolute joint `" + joint->name + "` needs a <limit> with lower < upper");
    }
    chain.axes.push_back(AxisLine{joint->name, base_from_link.translation, base_from_link.rotation * axis.normalized(),
                                  JointLimits{joint->limits->lower, joint->limits->upper}});
  }
  if (chain.axes.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, name + ": no revolute joint between base_link `" + spec.base_link +
                                                       "` and tip_link `" + spec.tip_link + "`");
  }
  chain.base_from_tip = base_from_link;
  if (!spec.camera_link.empty()) {
    const auto cam_joints = JointsBetween(model, spec.tip_link, spec.camera_link, &error);
    if (!error.empty())
      return Status::Error(ErrorCode::kInvalidInput, name + ": camera_link: " + error + " (tip_link)");
    Rigid3 tip_from_cam;
    for (const auto& joint : cam_joints) {
      if (joint->type != ::urdf::Joint::FIXED) {
        return Status::Error(ErrorCode::kInvalidInput, name + ": joint `" + joint->name + "` between tip_link `" +
                                                           spec.tip_link + "` and camera_link `" + spec.camera_link +
                                                           "` is " + JointTypeName(joint->type) + "; it must be fixed");
      }
      tip_from_cam = tip_from_cam * RigidOf(joint->parent_to_joint_origin_transform);
    }
    chain.tip_from_camera = tip_from_cam;
  }
  return chain;
}

}  // namespace selfcal::urdf
