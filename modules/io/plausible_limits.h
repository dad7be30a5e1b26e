// Limits of what a file may describe, shared by the readers of every format that gives such a value, so that
// one file's reader takes nothing another's refuses (detect writes no observations file calibrate refuses).
// Each is a physical bound, not a format's: a value beyond it is no measurement of an arm.
#pragma once

namespace selfcal::io {

// The largest translation component (m) of a transform a file gives: a flange, camera or base this far from
// the frame it is given in belongs to no arm (a link is at most 10 m, RobotModel::Validate; the largest
// industrial arms reach under 5 m). Observations files and poses lists (io/transform_yaml.h), per-image pose
// files (io/pose_files.h) and JSON pose files (io/json_pose_file.h).
inline constexpr double kMaxTranslationM = 10.0;

// A yardstick's or check distance's length: the distance between two different dots' centres, which no
// target places closer than 1 mm (a dot is wider than that, and a shorter length is no scale a camera could
// measure), in a cell no larger than 100 m. Observations files, a session's setup.json, name-dots --length-mm.
inline constexpr double kMinKnownDistanceM = 1e-3;
inline constexpr double kMaxKnownDistanceM = 100.0;

}  // namespace selfcal::io
