#include "io/fanuc_tracker_csv.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/terminal_text.h"
#include "geometry/rigid3.h"

namespace selfcal::io {

namespace {
constexpr int kColumns = 21;
constexpr double kMaxJointDeg = 720.0;
// A laser tracker measures to 80 m at most (Leica AT960: 80 m; FARO Vantage: 80 m): an SMR coordinate beyond
// 100 m is no measurement (the mutation campaign's 1e308 made a row's reflectors numerically collinear).
constexpr double kMaxSmrCoordinateMm = 1e5;

bool ParseDouble(const std::string& token, double* value) {
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  // The whole token (a NUL byte inside it would end strtod's reading early).
  return errno == 0 && end != token.c_str() && end == token.c_str() + token.size() && std::isfinite(*value);
}

// The three SMRs of a row span the nest frame (external::FrameFromThreePoints, the same test).
bool SpanAFrame(const std::array<Eigen::Vector3d, 3>& smr) {
  const Eigen::Vector3d e12 = smr[1] - smr[0], e13 = smr[2] - smr[0];
  return e12.norm() > 0 && e12.cross(e13).norm() > 1e-6 * e12.norm() * e13.norm();
}

// The problems of one row of 21 numbers ("" when none); fills *row.
std::string CheckRow(const std::vector<double>& values, const std::string& where, FanucTrackerRow* row) {
  std::string problems;
  for (int c = 0; c < 9; ++c) {
    if (std::abs(values[c]) > kMaxSmrCoordinateMm) {
      std::ostringstream v;
      v << values[c];
      problems += where + "column " + std::to_string(c + 1) + ": " + v.str() +
                  " mm is not an SMR coordinate (beyond the tracker's range of 100 m)\n";
    }
  }
  if (!problems.empty()) return problems;
  for (int k = 0; k < 3; ++k) {
    row->smr_in_tracker_m[k] = 1e-3 * Eigen::Vector3d(values[3 * k], values[3 * k + 1], values[3 * k + 2]);
  }
  if (!SpanAFrame(row->smr_in_tracker_m)) {
    problems += where + "the three SMRs are collinear or coincident: they give the nest no frame\n";
  }
  row->joints_rad.resize(6);
  for (int j = 0; j < 6; ++j) {
    const double deg = values[15 + j];
    if (std::abs(deg) > kMaxJointDeg) {
      problems += where + "J" + std::to_string(j + 1) + " = " + std::to_string(deg) + " deg outside [-720, 720]\n";
    }
    row->joints_rad[j] = DegToRad(deg);
  }
  return problems;
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
        problems += where + "'" + TerminalSafe(token) + "' is not a finite number\n";
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
    const std::string row_problems = CheckRow(values, where, &row);
    if (row_problems.empty()) rows.push_back(row);
    problems += row_problems;
  }
  if (!problems.empty()) {
    problems.pop_back();
    return Status::Error(ErrorCode::kInvalidInput, problems);
  }
  if (rows.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(std::max(line, 1)) +
                                                       ": no data rows (blank lines and # comments only)");
  }
  return rows;
}

}  // namespace selfcal::io
