#include "tracking/grid_identity.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include "tracking/planar_fit.h"

namespace selfcal::tracking {
namespace {

using Cell = std::pair<int, int>;  // lattice coordinates (i, j) along the seed's two steps

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Lattice {
  std::map<Cell, int> det_at;           // cell -> detection index
  std::vector<std::optional<Cell>> cell_of;  // detection index -> cell
  int ambiguities = 0;
  std::string ambiguity_note;
  int Assigned() const { return static_cast<int>(det_at.size()); }
};

class Grower {
 public:
  Grower(const std::vector<Eigen::Vector2d>& pts, double match_tolerance, int max_extent)
      : pts_(pts), tol_(match_tolerance), max_extent_(max_extent) {}

  // Grows a lattice from `seed`; nullopt when the seed has no confirmed 2 x 2 cell.
  std::optional<Lattice> Grow(int seed) const {
    const std::vector<int> near = NearestNeighbours(seed, 8);
    if (near.size() < 3) return std::nullopt;
    const Eigen::Vector2d s = pts_[static_cast<size_t>(seed)];
    const int n1 = near[0];
    const Eigen::Vector2d e1 = pts_[static_cast<size_t>(n1)] - s;
    int n2 = -1;
    for (size_t k = 1; k < near.size(); ++k) {
      const Eigen::Vector2d e = pts_[static_cast<size_t>(near[k])] - s;
      if (std::abs(Cross2(e1, e)) / (e1.norm() * e.norm()) > std::sqrt(0.5)) {
        n2 = near[k];
        break;
      }
    }
    if (n2 < 0) return std::nullopt;
    const Eigen::Vector2d e2 = pts_[static_cast<size_t>(n2)] - s;
    const double ratio = e1.norm() / e2.norm();
    if (ratio < 0.5 || ratio > 2.0) return std::nullopt;
    const double spacing = std::min(e1.norm(), e2.norm());
    const std::vector<int> diag = Within(s + e1 + e2, tol_ * spacing);
    if (diag.size() != 1 || diag[0] == seed || diag[0] == n1 || diag[0] == n2) return std::nullopt;

    Lattice lat;
    lat.cell_of.assign(pts_.size(), std::nullopt);
    auto assign = [&lat](const Cell& c, int d) {
      lat.det_at[c] = d;
      lat.cell_of[static_cast<size_t>(d)] = c;
    };
    assign({0, 0}, seed);
    assign({1, 0}, n1);
    assign({0, 1}, n2);
    assign({1, 1}, diag[0]);

    for (;;) {
      const std::optional<Eigen::Matrix3d> global = FitOf(lat, nullptr);
      if (!global) break;
      // Frontier: free cells next to assigned ones.
      std::map<Cell, std::vector<int>> proposals;  // cell -> candidate detections
      std::map<int, std::vector<Cell>> claims;     // detection -> cells proposing it
      for (const auto& [cell, det] : lat.det_at) {
        static const int kSteps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (const auto& st : kSteps) {
          const Cell c{cell.first + st[0], cell.second + st[1]};
          if (lat.det_at.count(c) != 0 || proposals.count(c) != 0) continue;
          if (std::abs(c.first) > max_extent_ || std::abs(c.second) > max_extent_) continue;
          const Eigen::Matrix3d h = LocalFit(lat, c).value_or(*global);
          const Eigen::Vector2d p = MapPoint(h, Eigen::Vector2d(c.first, c.second));
          const double step = std::min((MapPoint(h, Eigen::Vector2d(c.first + 1, c.second)) - p).norm(),
                                       (MapPoint(h, Eigen::Vector2d(c.first, c.second + 1)) - p).norm());
          if (!p.allFinite() || !std::isfinite(step)) continue;
          std::vector<int> cands = Within(p, tol_ * step);
          proposals[c] = cands;
          if (cands.size() > 1) {
            ++lat.ambiguities;
            std::ostringstream s_note;
            s_note << cands.size() << " detections within " << tol_ * step << " px of lattice cell (" << c.first
                   << ", " << c.second << ") predicted at (" << p.x() << ", " << p.y() << ")";
            lat.ambiguity_note = s_note.str();
          } else if (cands.size() == 1) {
            claims[cands[0]].push_back(c);
          }
        }
      }
      if (lat.ambiguities > 0) return lat;
      int added = 0;
      for (const auto& [det, cells] : claims) {
        if (lat.cell_of[static_cast<size_t>(det)].has_value() || cells.size() > 1) {
          ++lat.ambiguities;
          std::ostringstream s_note;
          s_note << "detection " << det << " at (" << pts_[static_cast<size_t>(det)].x() << ", "
                 << pts_[static_cast<size_t>(det)].y() << ") claimed by "
                 << (lat.cell_of[static_cast<size_t>(det)].has_value() ? "an assigned and a new" : "two new")
                 << " lattice cell";
          lat.ambiguity_note = s_note.str();
          continue;
        }
        assign(cells[0], det);
        ++added;
      }
      if (lat.ambiguities > 0 || added == 0) break;
    }
    return lat;
  }

  std::optional<Eigen::Matrix3d> FitOf(const Lattice& lat, const Cell* centre) const {
    std::vector<Eigen::Vector2d> from, to;
    for (const auto& [cell, det] : lat.det_at) {
      if (centre != nullptr && (std::abs(cell.first - centre->first) > 2 || std::abs(cell.second - centre->second) > 2)) {
        continue;
      }
      from.emplace_back(cell.first, cell.second);
      to.push_back(pts_[static_cast<size_t>(det)]);
    }
    if (centre != nullptr && from.size() < 6) return std::nullopt;
    return FitHomography(from, to);
  }

 private:
  std::optional<Eigen::Matrix3d> LocalFit(const Lattice& lat, const Cell& c) const { return FitOf(lat, &c); }

  std::vector<int> NearestNeighbours(int i, size_t k) const {
    std::vector<std::pair<double, int>> d;
    for (size_t j = 0; j < pts_.size(); ++j) {
      if (static_cast<int>(j) == i) continue;
      d.emplace_back((pts_[j] - pts_[static_cast<size_t>(i)]).squaredNorm(), static_cast<int>(j));
    }
    const size_t m = std::min(k, d.size());
    std::partial_sort(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(m), d.end());
    std::vector<int> out;
    for (size_t j = 0; j < m; ++j) out.push_back(d[j].second);
    return out;
  }

  std::vector<int> Within(const Eigen::Vector2d& p, double radius) const {
    std::vector<int> out;
    for (size_t j = 0; j < pts_.size(); ++j) {
      if ((pts_[j] - p).norm() <= radius) out.push_back(static_cast<int>(j));
    }
    return out;
  }

  const std::vector<Eigen::Vector2d>& pts_;
  double tol_;
  int max_extent_;
};

GridIdentityReport Fail(GridIdentityReport report, GridOutcome outcome, const std::string& message) {
  report.outcome = outcome;
  report.message = message;
  report.dots.clear();
  return report;
}

// Seeds: detections nearest the median position first (inside the grid, away from clutter).
std::vector<int> SeedOrder(const std::vector<Eigen::Vector2d>& pts) {
  const Eigen::Vector2d middle(Median([&] { std::vector<double> v; for (const auto& p : pts) v.push_back(p.x()); return v; }()),
                               Median([&] { std::vector<double> v; for (const auto& p : pts) v.push_back(p.y()); return v; }()));
  std::vector<int> order(pts.size());
  for (size_t k = 0; k < pts.size(); ++k) order[k] = static_cast<int>(k);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return (pts[static_cast<size_t>(a)] - middle).squaredNorm() < (pts[static_cast<size_t>(b)] - middle).squaredNorm();
  });
  return order;
}

// The lattice with the most dots grown from the first `attempts` seeds; stops early at a full grid.
std::optional<Lattice> GrowBest(const Grower& grower, const std::vector<int>& order, int attempts, int grid_size) {
  std::optional<Lattice> best;
  for (int a = 0; a < attempts; ++a) {
    std::optional<Lattice> lat = grower.Grow(order[static_cast<size_t>(a)]);
    if (!lat) continue;
    if (!best || lat->Assigned() > best->Assigned()) best = std::move(lat);
    if (best->Assigned() >= grid_size) break;
  }
  return best;
}

// The lattice's extent in cells and the homography image_from_cell fitted to all its dots.
struct LatticeFrame {
  int i_min = 1 << 30, i_max = -(1 << 30), j_min = 1 << 30, j_max = -(1 << 30);
  Eigen::Matrix3d image_from_cell;
  Eigen::Vector2d ImageOf(int i, int j) const { return MapPoint(image_from_cell, Eigen::Vector2d(i, j)); }
};

void FindExtent(const Lattice& lat, LatticeFrame* frame) {
  for (const auto& [cell, det] : lat.det_at) {
    frame->i_min = std::min(frame->i_min, cell.first);
    frame->i_max = std::max(frame->i_max, cell.first);
    frame->j_min = std::min(frame->j_min, cell.second);
    frame->j_max = std::max(frame->j_max, cell.second);
  }
}

// D6 over the whole lattice (the seed cell was taken without this check): every assigned position must
// have exactly one detection within the match tolerance. Empty when so, else what is wrong.
std::string CheckUniqueMatches(const Lattice& lat, const LatticeFrame& frame, const std::vector<Eigen::Vector2d>& pts,
                               double match_tolerance) {
  for (const auto& [cell, det] : lat.det_at) {
    const Eigen::Vector2d p = frame.ImageOf(cell.first, cell.second);
    const double step = std::min((frame.ImageOf(cell.first + 1, cell.second) - p).norm(),
                                 (frame.ImageOf(cell.first, cell.second + 1) - p).norm());
    int near = 0;
    for (const Eigen::Vector2d& q : pts) near += (q - p).norm() <= match_tolerance * step ? 1 : 0;
    if (near != 1) {
      std::ostringstream s;
      s << near << " detections within " << match_tolerance * step << " px of lattice cell (" << cell.first << ", "
        << cell.second << ") at (" << p.x() << ", " << p.y() << ")";
      return s.str();
    }
  }
  return "";
}

// Orientation: the origin corner (i0, j0), the inward steps (di, dj), and whether columns run along i.
struct Orientation {
  int i0, j0, di, dj;
  bool col_along_i;
};

Orientation Orient(const LatticeFrame& frame, int i0, int j0) {
  Orientation o{i0, j0, i0 == frame.i_min ? 1 : -1, j0 == frame.j_min ? 1 : -1, true};
  const Eigen::Vector2d a = frame.ImageOf(i0 + o.di, j0) - frame.ImageOf(i0, j0);
  const Eigen::Vector2d b = frame.ImageOf(i0, j0 + o.dj) - frame.ImageOf(i0, j0);
  o.col_along_i = Cross2(a, b) < 0;  // d_col x d_row < 0 (counter-clockwise on screen)
  return o;
}

// Whether every dot of the lattice lands inside rows x cols in orientation `o`.
bool Fits(const Lattice& lat, const Orientation& o, int rows, int cols) {
  for (const auto& [cell, det] : lat.det_at) {
    const int si = o.di * (cell.first - o.i0), sj = o.dj * (cell.second - o.j0);
    const int col = o.col_along_i ? si : sj, row = o.col_along_i ? sj : si;
    if (col < 0 || col >= cols || row < 0 || row >= rows) return false;
  }
  return true;
}

struct AreaRatios {
  int origin = -1;  // detection with the largest ratio, -1 if none
  double best = 0, runner_up = 0;
};

// Each dot's area over the median area of its lattice neighbours: the largest and the next.
AreaRatios LargestAreaRatios(const Lattice& lat, const std::vector<DotDetection>& detections) {
  AreaRatios r;
  for (const auto& [cell, det] : lat.det_at) {
    std::vector<double> around;
    for (int di = -1; di <= 1; ++di) {
      for (int dj = -1; dj <= 1; ++dj) {
        if (di == 0 && dj == 0) continue;
        const auto it = lat.det_at.find({cell.first + di, cell.second + dj});
        if (it != lat.det_at.end()) around.push_back(detections[static_cast<size_t>(it->second)].area_px2);
      }
    }
    const double ratio = detections[static_cast<size_t>(det)].area_px2 / Median(around);
    if (!std::isfinite(ratio)) continue;
    if (ratio > r.best) {
      r.runner_up = r.best;
      r.best = ratio;
      r.origin = det;
    } else if (ratio > r.runner_up) {
      r.runner_up = ratio;
    }
  }
  return r;
}

// The orientation from the larger origin dot; false, with `report` failed, when the marker is missing,
// ambiguous, off the corners, or the dots do not fit from it.
bool OrientFromMarker(const Lattice& lat, const LatticeFrame& frame, const std::vector<DotDetection>& detections,
                      const GridIdentityOptions& options, const std::string& extent, Orientation* chosen,
                      GridIdentityReport* report) {
  const AreaRatios r = LargestAreaRatios(lat, detections);
  report->origin_area_ratio = r.best;
  report->runner_up_area_ratio = r.runner_up;
  std::ostringstream ratios;
  ratios << "largest area ratio " << r.best << " (min " << options.min_origin_area_ratio << "), next " << r.runner_up
         << " (max " << options.max_runner_up_area_ratio << ")";
  if (r.origin < 0 || r.best < options.min_origin_area_ratio) {
    *report = Fail(*report, GridOutcome::kNoOriginDot, ratios.str());
    return false;
  }
  if (r.runner_up >= options.max_runner_up_area_ratio) {
    *report = Fail(*report, GridOutcome::kAmbiguousOrigin, ratios.str());
    return false;
  }
  report->origin_detection_index = r.origin;
  const Cell oc = *lat.cell_of[static_cast<size_t>(r.origin)];
  if ((oc.first != frame.i_min && oc.first != frame.i_max) || (oc.second != frame.j_min && oc.second != frame.j_max)) {
    *report = Fail(*report, GridOutcome::kOriginNotAtCorner, "the larger dot is not at a corner of the " + extent);
    return false;
  }
  *chosen = Orient(frame, oc.first, oc.second);
  if (!Fits(lat, *chosen, options.rows, options.cols)) {
    *report = Fail(*report, GridOutcome::kWrongSize,
                   extent + ": from the origin with the front-side handedness the dots do not fit " +
                       std::to_string(options.rows) + " rows x " + std::to_string(options.cols) +
                       " columns (mirrored image, or rows and columns swapped in the configuration)");
    return false;
  }
  report->orientation_from_marker = true;
  return true;
}

// Without a marker: of the corners the dots fit from, the one nearest the image's top left (smallest
// x + y). False, with `report` failed, when none fits.
bool OrientBySymmetry(const Lattice& lat, const LatticeFrame& frame, const GridIdentityOptions& options,
                      const std::string& extent, Orientation* chosen, GridIdentityReport* report) {
  bool any = false;
  double best_key = 0;
  for (const int i0 : {frame.i_min, frame.i_max}) {
    for (const int j0 : {frame.j_min, frame.j_max}) {
      const Orientation o = Orient(frame, i0, j0);
      if (!Fits(lat, o, options.rows, options.cols)) continue;
      const Eigen::Vector2d p = frame.ImageOf(i0, j0);
      const double key = p.x() + p.y();
      if (!any || key < best_key) {
        any = true;
        best_key = key;
        *chosen = o;
      }
    }
  }
  if (!any) {
    *report = Fail(*report, GridOutcome::kWrongSize, extent + ": no corner fits " + std::to_string(options.rows) +
                                                         " rows x " + std::to_string(options.cols) + " columns");
    return false;
  }
  const auto it = lat.det_at.find({chosen->i0, chosen->j0});
  report->origin_detection_index = it != lat.det_at.end() ? it->second : -1;
  report->orientation_from_marker = false;
  return true;
}

// Ids of the lattice's dots in orientation `o`, sorted by id, into report->dots; their (col, row) and
// pixel positions in lattice order into grid_pts and image_pts (the homography fit's input order).
void AssignIds(const Lattice& lat, const Orientation& o, const std::vector<Eigen::Vector2d>& pts, int cols,
               GridIdentityReport* report, std::vector<Eigen::Vector2d>* grid_pts,
               std::vector<Eigen::Vector2d>* image_pts) {
  for (const auto& [cell, det] : lat.det_at) {
    const int si = o.di * (cell.first - o.i0), sj = o.dj * (cell.second - o.j0);
    GridDot g;
    g.col = o.col_along_i ? si : sj;
    g.row = o.col_along_i ? sj : si;
    g.id = g.row * cols + g.col;
    g.detection_index = det;
    g.centroid_px = pts[static_cast<size_t>(det)];
    report->dots.push_back(g);
    grid_pts->emplace_back(g.col, g.row);
    image_pts->push_back(g.centroid_px);
  }
  std::sort(report->dots.begin(), report->dots.end(), [](const GridDot& a, const GridDot& b) { return a.id < b.id; });
}

// Each dot's residual to the grid homography h, their RMS and maximum, and the median spacing (px).
void MeasureResiduals(const Eigen::Matrix3d& h, GridIdentityReport* report) {
  double sum2 = 0, worst = 0;
  for (GridDot& g : report->dots) {
    g.residual_px = (MapPoint(h, Eigen::Vector2d(g.col, g.row)) - g.centroid_px).norm();
    sum2 += g.residual_px * g.residual_px;
    worst = std::max(worst, g.residual_px);
  }
  report->rms_residual_px = std::sqrt(sum2 / static_cast<double>(report->dots.size()));
  report->max_residual_px = worst;
  std::vector<double> steps;
  for (const GridDot& g : report->dots) {
    const Eigen::Vector2d p = MapPoint(h, Eigen::Vector2d(g.col, g.row));
    steps.push_back((MapPoint(h, Eigen::Vector2d(g.col + 1, g.row)) - p).norm());
    steps.push_back((MapPoint(h, Eigen::Vector2d(g.col, g.row + 1)) - p).norm());
  }
  report->median_spacing_px = Median(steps);
}

}  // namespace

const char* GridOutcomeName(GridOutcome outcome) {
  switch (outcome) {
    case GridOutcome::kNotRun: return "not_run";
    case GridOutcome::kSuccess: return "success";
    case GridOutcome::kTooFewDots: return "too_few_dots";
    case GridOutcome::kNoLattice: return "no_lattice";
    case GridOutcome::kAmbiguousMatch: return "ambiguous_match";
    case GridOutcome::kWrongSize: return "wrong_size";
    case GridOutcome::kIncomplete: return "incomplete";
    case GridOutcome::kNoOriginDot: return "no_origin_dot";
    case GridOutcome::kAmbiguousOrigin: return "ambiguous_origin";
    case GridOutcome::kOriginNotAtCorner: return "origin_not_at_corner";
    case GridOutcome::kLargeResidual: return "large_residual";
  }
  return "unknown";
}

Status GridIdentityOptions::Validate() const {
  std::ostringstream s;
  if (rows < 2 || cols < 2) s << "rows and cols must be >= 2, got " << rows << " x " << cols << "\n";
  if (!(min_origin_area_ratio > 1)) s << "min_origin_area_ratio must be > 1, got " << min_origin_area_ratio << "\n";
  if (!(max_runner_up_area_ratio >= 1 && max_runner_up_area_ratio <= min_origin_area_ratio)) {
    s << "max_runner_up_area_ratio must be in [1, min_origin_area_ratio], got " << max_runner_up_area_ratio << "\n";
  }
  if (!(match_tolerance > 0 && match_tolerance < 0.5)) {
    s << "match_tolerance must be in (0, 0.5) of the spacing, got " << match_tolerance << "\n";
  }
  if (!(max_residual_spacing > 0 && max_residual_spacing < 0.5)) {
    s << "max_residual_spacing must be in (0, 0.5), got " << max_residual_spacing << "\n";
  }
  if (!require_complete && origin_marker == OriginMarker::kNone) {
    s << "a partial grid (require_complete = false) needs the origin marker\n";
  }
  if (max_seed_attempts < 1) s << "max_seed_attempts must be >= 1, got " << max_seed_attempts << "\n";
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

Eigen::Vector3d GridPointInTarget(int row, int col, double spacing_m) {
  return Eigen::Vector3d(col * spacing_m, row * spacing_m, 0.0);
}

GridIdentityReport IdentifyGrid(const std::vector<DotDetection>& detections, const GridIdentityOptions& options) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid GridIdentityOptions:\n" << valid.message());
  std::vector<Eigen::Vector2d> pts;
  for (size_t k = 0; k < detections.size(); ++k) {
    SELFCAL_CHECK(detections[k].centroid_px.allFinite(), "detection " << k << " has a non-finite centroid");
    pts.push_back(detections[k].centroid_px);
  }
  GridIdentityReport report;
  const int rows = options.rows, cols = options.cols;
  const int needed = options.require_complete ? rows * cols : 4;
  if (static_cast<int>(pts.size()) < needed) {
    std::ostringstream s;
    s << detections.size() << " detections, need " << needed << " for a " << rows << " x " << cols << " grid";
    return Fail(report, GridOutcome::kTooFewDots, s.str());
  }

  const std::vector<int> order = SeedOrder(pts);
  const Grower grower(pts, options.match_tolerance, 2 * std::max(rows, cols));
  const int attempts = std::min<int>(options.max_seed_attempts, static_cast<int>(order.size()));
  const std::optional<Lattice> best = GrowBest(grower, order, attempts, rows * cols);
  if (!best) {
    return Fail(report, GridOutcome::kNoLattice,
                "no seed among the " + std::to_string(attempts) + " nearest the middle closed a 2 x 2 lattice cell");
  }
  const Lattice& lat = *best;
  report.assigned = lat.Assigned();
  report.unassigned_detections = static_cast<int>(pts.size()) - lat.Assigned();
  if (lat.ambiguities > 0) return Fail(report, GridOutcome::kAmbiguousMatch, lat.ambiguity_note);

  LatticeFrame frame;
  FindExtent(lat, &frame);
  const int n_i = frame.i_max - frame.i_min + 1, n_j = frame.j_max - frame.j_min + 1;
  std::ostringstream extent_stream;
  extent_stream << "lattice of " << n_i << " x " << n_j << " cells with " << lat.Assigned() << " dots, configured "
                << rows << " x " << cols;
  const std::string extent = extent_stream.str();
  if (std::max(n_i, n_j) > std::max(rows, cols) || std::min(n_i, n_j) > std::min(rows, cols)) {
    return Fail(report, GridOutcome::kWrongSize, extent);
  }
  if (options.require_complete && lat.Assigned() < rows * cols) {
    return Fail(report, GridOutcome::kIncomplete, extent);
  }
  const std::optional<Eigen::Matrix3d> image_from_cell = grower.FitOf(lat, nullptr);
  if (!image_from_cell) return Fail(report, GridOutcome::kNoLattice, "degenerate lattice: " + extent);
  frame.image_from_cell = *image_from_cell;
  const std::string ambiguous = CheckUniqueMatches(lat, frame, pts, options.match_tolerance);
  if (!ambiguous.empty()) return Fail(report, GridOutcome::kAmbiguousMatch, ambiguous);

  Orientation chosen{};
  const bool oriented = options.origin_marker == OriginMarker::kLargerDot
                            ? OrientFromMarker(lat, frame, detections, options, extent, &chosen, &report)
                            : OrientBySymmetry(lat, frame, options, extent, &chosen, &report);
  if (!oriented) return report;

  // Ids, and the homography of the whole grid in (col, row) units.
  std::vector<Eigen::Vector2d> grid_pts, image_pts;
  AssignIds(lat, chosen, pts, cols, &report, &grid_pts, &image_pts);
  const std::optional<Eigen::Matrix3d> h = FitHomography(grid_pts, image_pts);
  if (!h) return Fail(report, GridOutcome::kNoLattice, "degenerate grid homography: " + extent);
  report.image_from_grid = *h;
  MeasureResiduals(*h, &report);
  const double limit = options.max_residual_spacing * report.median_spacing_px;
  if (!(report.max_residual_px <= limit)) {
    std::ostringstream s;
    s << "a dot is " << report.max_residual_px << " px from the grid homography (max " << limit << " = "
      << options.max_residual_spacing << " x spacing " << report.median_spacing_px << ", rms "
      << report.rms_residual_px << ")";
    return Fail(report, GridOutcome::kLargeResidual, s.str());
  }
  report.outcome = GridOutcome::kSuccess;
  std::ostringstream s;
  s << report.dots.size() << " ids from a " << extent
    << (report.orientation_from_marker ? ", origin from the larger dot" : ", orientation up to the grid's symmetry (no marker)");
  report.message = s.str();
  return report;
}

}  // namespace selfcal::tracking
