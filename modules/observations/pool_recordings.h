// Several recordings of one arm calibrated together: each observations file a scene of its own (the board
// may have moved between them), pooled into one set that SeparateScenes then splits into separate points.
//
//   PoolRecordings({{"s1", set1}, {"s3", set3}})
//     poses      every recording's, in order, each id prefixed "label/" (two recordings may both have a
//                "pose_00"), each in scene "label" (a pose that names a scene keeps it as "label/scene")
//     the rest   the first recording's robot, camera, noise, yardsticks and check distances
//
// Refused, naming the recording and what differs: another robot description (joint count or nominal
// parameters), another image size, joint angles pooled with flange poses, or an empty label.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "base/status.h"
#include "observations/observation_set.h"

namespace selfcal {

struct Recording {
  std::string label;  // the scene's name (e.g. the file name without its extension)
  ObservationSet observations;
};

Result<ObservationSet> PoolRecordings(const std::vector<Recording>& recordings);

}  // namespace selfcal
