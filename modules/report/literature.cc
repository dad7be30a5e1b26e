#include "report/literature.h"

#include <cmath>

namespace selfcal::report {

const std::vector<PaperTable2Row>& MengZhuang2001Table2() {
  // trajectory, noise px, position mm (mean, SD), orientation 1e-4 rad (mean, SD), f_x px (mean, SD)
  static const std::vector<PaperTable2Row> rows = {
      {"initial", 0.2, {3.0427, 1.1051}, {1.4918, 2.5354}, {0.2249, 0.2374}},
      {"optimal", 0.2, {0.2809, 0.2452}, {1.0701, 1.4532}, {0.1539, 0.2128}},
      {"initial", 0.5, {6.9837, 2.6475}, {4.0876, 7.1762}, {0.6181, 0.7324}},
      {"optimal", 0.5, {0.3035, 0.2826}, {2.4016, 3.2432}, {0.3458, 0.4791}},
  };
  return rows;
}

const PaperTable2Row* NearestTable2Row(const std::string& trajectory, double noise_px) {
  const PaperTable2Row* best = nullptr;
  for (const PaperTable2Row& row : MengZhuang2001Table2()) {
    if (row.trajectory != trajectory) continue;
    if (best == nullptr || std::abs(row.noise_px - noise_px) < std::abs(best->noise_px - noise_px)) best = &row;
  }
  return best;
}

}  // namespace selfcal::report
