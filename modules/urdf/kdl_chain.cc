#include "urdf/kdl_chain.h"

#include <algorithm>
#include <vector>

namespace selfcal::urdf {
namespace {

KDL::Frame FrameOf(const ::urdf::Pose& pose) {
  return KDL::Frame(KDL::Rotation::Quaternion(pose.rotation.x, pose.rotation.y, pose.rotation.z, pose.rotation.w),
                    KDL::Vector(pose.position.x, pose.position.y, pose.position.z));
}

// The segment of the link below `joint`: the joint's origin, then its motion about or along its axis.
Result<KDL::Segment> SegmentOf(const ::urdf::Joint& joint, const std::string& name) {
  const KDL::Frame origin = FrameOf(joint.parent_to_joint_origin_transform);
  const KDL::Vector axis = origin.M * KDL::Vector(joint.axis.x, joint.axis.y, joint.axis.z);
  switch (joint.type) {
    case ::urdf::Joint::REVOLUTE:
    case ::urdf::Joint::CONTINUOUS:
      return KDL::Segment(joint.child_link_name, KDL::Joint(joint.name, origin.p, axis, KDL::Joint::RotAxis), origin);
    case ::urdf::Joint::PRISMATIC:
      return KDL::Segment(joint.child_link_name, KDL::Joint(joint.name, origin.p, axis, KDL::Joint::TransAxis),
                          origin);
    case ::urdf::Joint::FIXED:
      return KDL::Segment(joint.child_link_name, KDL::Joint(joint.name, KDL::Joint::None), origin);
    default:
      return Status::Error(ErrorCode::kInvalidInput, name + ": joint `" + joint.name +
                                                         "` is neither revolute, continuous, prismatic nor fixed");
  }
}

}  // namespace

Result<KDL::Chain> KdlChainOf(const ::urdf::ModelInterface& model, const std::string& name,
                              const std::string& base_link, const std::string& tip_link) {
  if (!model.getLink(base_link)) {
    return Status::Error(ErrorCode::kInvalidInput, name + ": no link `" + base_link + "`");
  }
  std::vector<::urdf::JointConstSharedPtr> joints;  // tip upwards
  ::urdf::LinkConstSharedPtr link = model.getLink(tip_link);
  if (!link) return Status::Error(ErrorCode::kInvalidInput, name + ": no link `" + tip_link + "`");
  while (link->name != base_link) {
    const ::urdf::JointConstSharedPtr joint = link->parent_joint;
    ::urdf::LinkConstSharedPtr parent = joint ? model.getLink(joint->parent_link_name) : nullptr;
    if (!joint || !parent || joints.size() > model.joints_.size()) {
      return Status::Error(ErrorCode::kInvalidInput,
                           name + ": no chain from `" + base_link + "` to `" + tip_link + "`");
    }
    joints.push_back(joint);
    link = parent;
  }
  std::reverse(joints.begin(), joints.end());
  KDL::Chain chain;
  for (const ::urdf::JointConstSharedPtr& joint : joints) {
    Result<KDL::Segment> segment = SegmentOf(*joint, name);
    if (!segment.ok()) return segment.status();
    chain.addSegment(*segment);
  }
  return chain;
}

}  // namespace selfcal::urdf
