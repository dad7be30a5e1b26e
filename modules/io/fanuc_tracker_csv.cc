#include "io/fanuc_tracker_csv.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "geometry/rigid3.h"

namespace selfcal::io {

namespace {
constexpr int kColumns = 21;
constexpr double kMaxJointDeg = 720.0;

bool ParseDouble(const std::string& token, double* value) {
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return errno == 0 && end != token.c_str() && *end == '\0' && std::isfinite(*value);
}
}  // namespace

Result<std::vector<FanucTrackerRow>> LoadFanucTrackerCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(ErrorCode::kInvalidInput, path + ": cannot open");
  std::vector<FanucTrackerRow> rows;
  std::string text, problems;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    const std::string where = path + ":" + std::to_string(line) + ": ";
    const size_t first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos || text[first] == '#') continue;
    std::istringstream tokens(text);
    std::vector<double> values;
    std::string token;
    bool bad = false;
    while (tokens >> token) {
      double v = 0;
      if (!ParseDouble(token, &v)) {
        problems += where + "'" + token + "' is not a finite number\n";
        bad = true;
        break;
      }
      values.push_back(v);
    }
    if (bad) continue;
    if (static_cast<int>(values.size()) != kColumns) {
      problems += where + std::to_string(values.size()) + " columns, expected " + std::to_string(kColumns) + "\n";
      continue;
    }
    FanucTrackerRow row;
    row.line = line;
    for (int k = 0; k < 3; ++k) {
      row.smr_in_tracker_m[k] = 1e-3 * Eigen::Vector3d(values[3 * k], values[3 * k + 1], values[3 * k + 2]);
    }
    row.joints_rad.resize(6);
    for (int j = 0; j < 6; ++j) {
      const double deg = values[15 + j];
      if (std::abs(deg) > kMaxJointDeg) {
        problems += where + "J" + std::to_string(j + 1) + " = " + std::to_string(deg) + " deg outside [-720, 720]\n";
        bad = true;
      }
      row.joints_rad[j] = DegToRad(deg);
    }
    if (!bad) rows.push_back(row);
  }
  if (!problems.empty()) {
    problems.pop_back();
    return Status::Error(ErrorCode::kInvalidInput, problems);
  }
  if (rows.empty()) return Status::Error(ErrorCode::kInvalidInput, path + ": no data rows");
  return rows;
}

}  // namespace selfcal::io
