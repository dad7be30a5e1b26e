// Laser-tracker nest files of the Fanuc kinematic-identification data set (RABKKK/LaserTrackerPoseData4KinIdent,
// `N1N2N3Jval*.csv`): one whitespace-separated row per robot pose, 21 numbers:
//   cols 1-9    SMR N1, N2, N3 positions (x y z each) in the tracker frame, mm
//   cols 10-15  unused (zeros in the published files; read and ignored)
//   cols 16-21  controller joint readings J1..J6, degrees (Fanuc convention: J3 is reported relative to J2;
//               the reader does not interpret it, see external/tracker_identification.h)
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"

namespace selfcal::io {

struct FanucTrackerRow {
  std::array<Eigen::Vector3d, 3> smr_in_tracker_m;  // N1, N2, N3 (converted from mm)
  Eigen::VectorXd joints_rad;                       // J1..J6 as reported (converted from degrees)
  int line = 0;                                     // 1-based line in the file
};

// Reads every row. The whole file is refused (ErrorCode::kInvalidInput, naming file:line) if a row does not have
// exactly 21 numbers, a number does not parse or is not finite, an SMR coordinate lies beyond 100 m (1e5 mm:
// a tracker's range), a row's three SMRs are collinear or coincident (no nest frame), a joint lies outside
// [-720, 720] deg, or the file holds no row. Blank lines and lines starting with '#' are skipped.
Result<std::vector<FanucTrackerRow>> LoadFanucTrackerCsv(const std::string& path);

}  // namespace selfcal::io
