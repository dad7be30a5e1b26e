#include "detection/chessboard.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "detection/corner_refine.h"

namespace selfcal::detection {

namespace {

// An ordering: canonical id k takes OpenCV's corner source[k].
using Ordering = std::vector<int>;

// The symmetries of the rows x cols grid: index maps (r, c) -> OpenCV (r', c'); the transposing ones only
// when the grid is square.
std::vector<Ordering> GridSymmetries(int rows, int cols) {
  std::vector<Ordering> out;
  for (int sym = 0; sym < 8; ++sym) {
    const bool transpose = (sym & 4) != 0;
    if (transpose && rows != cols) continue;
    Ordering o(static_cast<size_t>(rows * cols));
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        int a = transpose ? c : r, b = transpose ? r : c;
        if (sym & 1) a = rows - 1 - a;
        if (sym & 2) b = cols - 1 - b;
        o[static_cast<size_t>(r * cols + c)] = a * cols + b;
      }
    }
    out.push_back(std::move(o));
  }
  return out;
}

// Mean image step to the next column and to the next row under `o`; their cross product u_c v_r - v_c u_r.
double Handedness(const std::vector<Eigen::Vector2d>& p, const Ordering& o, int rows, int cols) {
  Eigen::Vector2d d_col = Eigen::Vector2d::Zero(), d_row = Eigen::Vector2d::Zero();
  auto at = [&](int r, int c) -> const Eigen::Vector2d& { return p[static_cast<size_t>(o[static_cast<size_t>(r * cols + c)])]; };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) d_col += at(r, c + 1) - at(r, c);
  }
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c < cols; ++c) d_row += at(r + 1, c) - at(r, c);
  }
  return d_col.x() * d_row.y() - d_col.y() * d_row.x();
}

double GreyAt(const vpImage<unsigned char>& image, const Eigen::Vector2d& p) {
  const int u = std::clamp(static_cast<int>(std::lround(p.x())), 0, static_cast<int>(image.getWidth()) - 1);
  const int v = std::clamp(static_cast<int>(std::lround(p.y())), 0, static_cast<int>(image.getHeight()) - 1);
  return image[static_cast<unsigned>(v)][static_cast<unsigned>(u)];
}

// Mean grey level of the central part of each inner square (row-major, (rows - 1) x (cols - 1)) under `o`.
std::vector<double> SquareLevels(const vpImage<unsigned char>& image, const std::vector<Eigen::Vector2d>& p,
                                 const Ordering& o, int rows, int cols) {
  auto at = [&](int r, int c) -> const Eigen::Vector2d& { return p[static_cast<size_t>(o[static_cast<size_t>(r * cols + c)])]; };
  std::vector<double> levels;
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      double sum = 0;
      int n = 0;
      for (double s = 0.3; s < 0.71; s += 0.1) {
        for (double t = 0.3; t < 0.71; t += 0.1) {
          const Eigen::Vector2d q = (1 - s) * (1 - t) * at(r, c) + s * (1 - t) * at(r, c + 1) +
                                    (1 - s) * t * at(r + 1, c) + s * t * at(r + 1, c + 1);
          sum += GreyAt(image, q);
          ++n;
        }
      }
      levels.push_back(sum / n);
    }
  }
  return levels;
}

// The light squares' mean level minus the dark squares' when square (0, 0) is taken as dark (negative when
// it is light); -infinity when fewer than 90 % of the squares are on their colour's side of the midpoint
// (the colours cannot be told, or square (0, 0) is light).
double DarkFirstSquareContrast(const std::vector<double>& levels, int cols) {
  const int sq_cols = cols - 1;
  double even = 0, odd = 0;
  int n_even = 0, n_odd = 0;
  for (size_t k = 0; k < levels.size(); ++k) {
    const int r = static_cast<int>(k) / sq_cols, c = static_cast<int>(k) % sq_cols;
    if ((r + c) % 2 == 0) {
      even += levels[k];
      ++n_even;
    } else {
      odd += levels[k];
      ++n_odd;
    }
  }
  if (n_even == 0 || n_odd == 0) return -std::numeric_limits<double>::infinity();
  even /= n_even;
  odd /= n_odd;
  const double mid = 0.5 * (even + odd);
  int agreeing = 0;
  for (size_t k = 0; k < levels.size(); ++k) {
    const int r = static_cast<int>(k) / sq_cols, c = static_cast<int>(k) % sq_cols;
    const bool dark_expected = (r + c) % 2 == 0;
    agreeing += (levels[k] < mid) == dark_expected ? 1 : 0;
  }
  if (agreeing < 0.9 * static_cast<double>(levels.size())) return -std::numeric_limits<double>::infinity();
  return odd - even;
}

std::vector<Eigen::Vector2d> Apply(const std::vector<Eigen::Vector2d>& p, const Ordering& o) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(o.size());
  for (int k : o) out.push_back(p[static_cast<size_t>(k)]);
  return out;
}

double RmsDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  double sum = 0;
  for (size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

double MinSpacing(const std::vector<cv::Point2f>& c, int rows, int cols) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < rows; ++r) {
    for (int k = 0; k < cols; ++k) {
      const cv::Point2f& p = c[static_cast<size_t>(r * cols + k)];
      if (k + 1 < cols) best = std::min(best, static_cast<double>(cv::norm(c[static_cast<size_t>(r * cols + k + 1)] - p)));
      if (r + 1 < rows) best = std::min(best, static_cast<double>(cv::norm(c[static_cast<size_t>((r + 1) * cols + k)] - p)));
    }
  }
  return best;
}

// Each corner refined by RefineCorner along its two edges (towards its grid neighbours), from OpenCV's
// unrefined corner, over a radius of 0.45 times the distance to its nearest neighbour; a corner it cannot
// refine keeps cornerSubPix's position in *refined.
void RefineAlongEdges(const vpImage<unsigned char>& image, const std::vector<cv::Point2f>& rough,
                      const ChessboardOptions& options, std::vector<cv::Point2f>* refined) {
  const int rows = options.rows, cols = options.cols;
  auto at = [&](int r, int c) {
    const cv::Point2f& p = rough[static_cast<size_t>(r * cols + c)];
    return Eigen::Vector2d(p.x, p.y);
  };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d along_col = at(r, std::min(c + 1, cols - 1)) - at(r, std::max(c - 1, 0));
      const Eigen::Vector2d along_row = at(std::min(r + 1, rows - 1), c) - at(std::max(r - 1, 0), c);
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& [dr, dc] : {std::pair{0, 1}, std::pair{0, -1}, std::pair{1, 0}, std::pair{-1, 0}}) {
        if (r + dr >= 0 && r + dr < rows && c + dc >= 0 && c + dc < cols) nearest = std::min(nearest, (at(r + dr, c + dc) - at(r, c)).norm());
      }
      CornerRefineOptions ro;
      ro.radius_px = 0.45 * nearest;
      ro.edge_directions_px = {along_col.normalized(), along_row.normalized()};
      // Narrow: a ChArUco board's markers (unknown here) may run parallel to the edges a few pixels away.
      ro.band_px = 1.5;
      if (!(ro.radius_px >= 1.5) || !ro.edge_directions_px[0].allFinite() || !ro.edge_directions_px[1].allFinite()) continue;
      const CheckedCorner checked = RefineCornerChecked(image, at(r, c), ro, 1.5);
      const RefinedCorner& chosen = checked.agree ? checked.large : checked.small;
      if (chosen.ok) {
        (*refined)[static_cast<size_t>(r * cols + c)] = cv::Point2f(static_cast<float>(chosen.px.x()), static_cast<float>(chosen.px.y()));
      }
    }
  }
}

}  // namespace

Status ChessboardOptions::Validate() const {
  std::ostringstream s;
  if (rows < 2 || cols < 2 || rows > 1000 || cols > 1000) {
    s << "a chessboard needs at least 2 x 2 (and at most 1000 x 1000) inner corners, got " << rows << " x " << cols << "\n";
  }
  if (!(min_colour_contrast > 0 && min_colour_contrast < 255)) {
    s << "min_colour_contrast must be in (0, 255) grey levels, got " << min_colour_contrast << "\n";
  }
  if (max_subpix_half_window_px < 1) s << "max_subpix_half_window_px must be >= 1, got " << max_subpix_half_window_px << "\n";
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

const char* OrderingCueName(OrderingCue cue) {
  switch (cue) {
    case OrderingCue::kNone: return "none";
    case OrderingCue::kColour: return "colour";
    case OrderingCue::kContinuity: return "continuity";
    case OrderingCue::kFirstImage: return "first image";
  }
  return "unknown";
}

ChessboardDetection OrderChessboardCorners(const vpImage<unsigned char>& image, const std::vector<Eigen::Vector2d>& corners,
                                           const ChessboardOptions& options, const std::vector<Eigen::Vector2d>& previous) {
  const int rows = options.rows, cols = options.cols;
  SELFCAL_CHECK(corners.size() == static_cast<size_t>(rows * cols),
                "OrderChessboardCorners: " << corners.size() << " corners for a " << rows << " x " << cols << " grid");
  // 1. handedness.
  std::vector<Ordering> candidates;
  for (Ordering& o : GridSymmetries(rows, cols)) {
    if (Handedness(corners, o, rows, cols) < 0) candidates.push_back(std::move(o));
  }
  // 2. colour.
  std::vector<double> contrast;
  for (const Ordering& o : candidates) {
    contrast.push_back(DarkFirstSquareContrast(SquareLevels(image, corners, o, rows, cols), cols));
  }
  std::vector<size_t> kept;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (contrast[k] >= options.min_colour_contrast) kept.push_back(k);
  }
  ChessboardDetection out;
  out.cue = OrderingCue::kColour;
  if (kept.size() != 1) {
    if (kept.empty()) {
      for (size_t k = 0; k < candidates.size(); ++k) kept.push_back(k);
    }
    // 3. continuity, or the first image's rule.
    const bool have_previous = previous.size() == corners.size();
    out.cue = have_previous ? OrderingCue::kContinuity : OrderingCue::kFirstImage;
    double best = std::numeric_limits<double>::infinity();
    size_t chosen = kept[0];
    for (size_t k : kept) {
      const std::vector<Eigen::Vector2d> ordered = Apply(corners, candidates[k]);
      const double score = have_previous ? RmsDistance(ordered, previous) : ordered[0].x() + ordered[0].y();
      if (score < best) {
        best = score;
        chosen = k;
      }
    }
    kept = {chosen};
  }
  out.found = true;
  out.corners_px = Apply(corners, candidates[kept[0]]);
  out.colour_contrast = std::isfinite(contrast[kept[0]]) ? contrast[kept[0]] : 0.0;
  return out;
}

ChessboardDetection DetectChessboard(const vpImage<unsigned char>& image, const ChessboardOptions& options,
                                     const std::vector<Eigen::Vector2d>& previous) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid ChessboardOptions:\n" << valid.message());
  SELFCAL_CHECK(image.getWidth() > 0 && image.getHeight() > 0, "DetectChessboard: empty image");
  const cv::Mat mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1,
                    const_cast<unsigned char*>(image.bitmap));
  std::vector<cv::Point2f> found;
  const cv::Size pattern(options.cols, options.rows);
  ChessboardDetection out;
  if (!cv::findChessboardCorners(mat, pattern, found, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE) ||
      found.size() != static_cast<size_t>(options.rows * options.cols)) {
    out.message = "no " + std::to_string(options.rows) + " x " + std::to_string(options.cols) +
                  " chessboard (inner corners) found";
    return out;
  }
  const double spacing = MinSpacing(found, options.rows, options.cols);
  const int half = std::clamp(static_cast<int>(std::floor(0.4 * spacing)), 1, options.max_subpix_half_window_px);
  std::vector<cv::Point2f> rough = found;
  cv::cornerSubPix(mat, found, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  RefineAlongEdges(image, rough, options, &found);
  std::vector<Eigen::Vector2d> corners;
  for (const cv::Point2f& p : found) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      out.message = "a refined chessboard corner is not finite";
      return out;
    }
    corners.emplace_back(p.x, p.y);
  }
  return OrderChessboardCorners(image, corners, options, previous);
}

}  // namespace selfcal::detection
