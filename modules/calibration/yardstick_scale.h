// The yardstick as a check of a joint-angle calibration. Images alone measure no length: the bundle's
// metric scale is the yardstick's (bundle_adjustment.h). The robot description's link lengths are a second,
// independent scale, so the calibrated arm's free lengths against the description's say whether the two
// agree: a uniform factor s = 1 + sum(c_i n_i) / sum(n_i^2) over the free link lengths n_i of at least
// kMinScaleLengthM (c_i their corrections), with its standard deviation from the bundle's covariance. A real
// arm differs from its description by fractions of a millimetre per link, far below kMaxScaleDeviation;
// a yardstick whose length or ends are wrong scales every free length with it (a 198 mm yardstick typed as
// 189 mm makes the arm 4.5 % smaller and changes no image).
#pragma once

#include <string>
#include <vector>

#include "bundle/bundle_adjustment.h"
#include "kinematics/robot_model.h"

namespace selfcal::calibration {

inline constexpr double kMinScaleLengthM = 0.01;    // shorter nominal lengths say little about a scale
inline constexpr double kMaxScaleDeviation = 0.01;  // 1 %: no real arm is uniformly this far from its drawing

struct YardstickScale {
  bool available = false;
  std::string reason;               // why not, when not available
  int yardsticks = 0;               // in the set
  std::vector<std::string> lengths; // the free link lengths that entered s
  double scale = 1;                 // s
  double stddev = 0;                // of s, from the bundle's covariance (NaN without one)
};

// The scale of a converged bundle on a joint-angle set (`robot`: the description it corrected).
YardstickScale YardstickScaleOf(const RobotModel& robot, const bundle::BundleReport& bundle, int yardsticks);

}  // namespace selfcal::calibration
