// The values of a URDF that urdfdom takes without a word but that cannot describe an arm (internal to the
// module; urdf_parse.cc calls it between tinyxml and urdfdom). urdfdom ignores an element it does not know
// (a misspelt `<aixs>`: the joint silently turns about x), normalises any axis (`1e23 0 1` becomes x), takes
// an origin of 1e308, and gives a revolute joint's missing `lower` or `upper` the value 0 (a misspelt
// `upepr=`: every pose outside the limits). Each is refused here naming the file and the line.
#pragma once

#include <string>

#include "base/status.h"

class TiXmlDocument;

namespace selfcal::urdf {

// The largest origin coordinate (1 km), rpy angle (100 rad) and axis component (1e6) a URDF may give.
inline constexpr double kMaxUrdfLengthM = 1e3;
inline constexpr double kMaxUrdfAngleRad = 100.0;
inline constexpr double kMaxUrdfAxisComponent = 1e6;

// The joints of `xml` (the URDF `name`): known child elements only, an axis and origins within the limits
// above, a revolute joint's <limit> with both `lower` and `upper`. Ok or kInvalidInput "<name>:<line>: ...".
Status CheckUrdfValues(const TiXmlDocument& xml, const std::string& name);

}  // namespace selfcal::urdf
