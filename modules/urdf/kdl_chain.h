// The KDL chain between two links of a URDF, built from urdfdom's model (module-private).
//
// URDF semantics: a child link's frame is its parent joint's origin in the parent link's frame, then the
// joint's motion about (revolute, continuous) or along (prismatic) the joint's axis, expressed in that
// origin frame; a fixed joint adds its origin only. Built here rather than with kdl_parser, which pulls
// in ROS's console and class-loader libraries (about 40 shared libraries, 14 ms of every process start);
// the tests compare it with kdl_parser's tree on the shipped URDFs.
#pragma once

#include <string>

#include <kdl/chain.hpp>
#include <urdf_model/model.h>

#include "base/status.h"

namespace selfcal::urdf {

// The segments from `base_link` down to `tip_link`. kInvalidInput (naming `name` and the link or joint)
// when a link is missing, `tip_link` does not descend from `base_link`, or a joint on the way is neither
// revolute, continuous, prismatic nor fixed.
Result<KDL::Chain> KdlChainOf(const ::urdf::ModelInterface& model, const std::string& name,
                              const std::string& base_link, const std::string& tip_link);

}  // namespace selfcal::urdf
