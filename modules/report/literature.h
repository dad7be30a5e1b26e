// Figures published by others that reports print beside ours, as data: one table per source, each row
// as printed in the source (its units in the field names), never retyped inside formatting code.
#pragma once

#include <string>
#include <vector>

namespace selfcal::report {

struct MeanSd {
  double mean = 0;
  double sd = 0;
};

// Meng & Zhuang, "Self-Calibration of Camera-Equipped Robot Manipulators", IJRR 20(11), 2001, Table 2:
// pose measurement errors over pose pairs and runs, per trajectory and pixel noise (noise I = 0.2 px,
// noise II = 0.5 px), mean and SD.
struct PaperTable2Row {
  std::string trajectory;  // "initial" or "optimal"
  double noise_px = 0;
  MeanSd position_mm;
  MeanSd orientation_1e4rad;
  MeanSd fx_px;
};
const std::vector<PaperTable2Row>& MengZhuang2001Table2();

// The row of `trajectory` at the table's noise level nearest to `noise_px`; nullptr when the table has
// no row for that trajectory.
const PaperTable2Row* NearestTable2Row(const std::string& trajectory, double noise_px);

}  // namespace selfcal::report
