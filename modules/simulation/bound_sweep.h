// What setup would make the paper's Table 2 figures reachable? The two-view Cramer-Rao bound of a
// canonical pair over a grid of field of view, depth spread and baseline (the paper does not state its
// scene or optics).
//
// Canonical pair: camera 1 at the origin looking along +z; num_points dots uniform in depth over
// depth_m * [1 - spread/2, 1 + spread/2] and laterally over 80 % of the image at their depth, every dot
// in view of both cameras; camera 2 displaced by baseline_ratio * depth_m along x and turned to look at
// the scene centre with an aim point 0.1 * depth_m off in y (so the optical axes do not intersect).
#pragma once

#include <cstdint>
#include <vector>

#include "base/progress.h"

namespace selfcal::simulation {

struct BoundSetup {
  double fx_px = 1000;        // with a 640x480 image: horizontal field of view 2 atan(320 / fx)
  double depth_m = 0.65;
  double depth_spread_ratio = 0.5;
  double baseline_ratio = 0.3;
  int num_points = 80;
  double sigma_px = 0.2;
};

struct BoundPoint {
  BoundSetup setup;
  bool ok_fx_known = false;    // the bound exists with f_x known
  bool ok_fx_unknown = false;  // false when f_x is unobservable from the pair (singular information)
  double horizontal_fov_deg = 0;
  double baseline_m = 0;
  // RMS bounds; position = ||t|| * direction error.
  double orientation_rad_fx_unknown = 0, position_m_fx_unknown = 0, fx_px = 0;
  double orientation_rad_fx_known = 0, position_m_fx_known = 0;
};

// `progress` (optional) is told each setup done.
std::vector<BoundPoint> SweepTwoViewBound(const std::vector<BoundSetup>& setups, uint64_t seed,
                                          ProgressSink* progress = nullptr);

// The default grid: fx {500, 1000, 2000, 4000} x spread {0.05, 0.3, 0.7} x baseline {0.1, 0.3, 0.6, 1.0},
// then fx 300 (94 deg) at spread 0.7, baseline 0.3 and 1.0, and 800 and 8000 dots at fx 500, spread 0.7, 0.3.
std::vector<BoundSetup> DefaultBoundGrid(double sigma_px);

}  // namespace selfcal::simulation
