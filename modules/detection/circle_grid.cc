#include "detection/circle_grid.h"

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/LU>
#include <opencv2/calib3d.hpp>

#include "base/status.h"

namespace selfcal::detection {

namespace {

// Sign of the determinant of the affine map that fits layout -> image best (least squares).
double AffineDeterminant(const CircleGridLayout& layout, const std::vector<Eigen::Vector2d>& px) {
  Eigen::Vector2d ml = Eigen::Vector2d::Zero(), mp = Eigen::Vector2d::Zero();
  const int n = layout.size();
  for (int k = 0; k < n; ++k) ml += layout.Point(k), mp += px[static_cast<size_t>(k)];
  ml /= n;
  mp /= n;
  Eigen::Matrix2d ll = Eigen::Matrix2d::Zero(), pl = Eigen::Matrix2d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d l = layout.Point(k) - ml, p = px[static_cast<size_t>(k)] - mp;
    ll += l * l.transpose();
    pl += p * l.transpose();
  }
  return (pl * ll.inverse()).determinant();
}

// cv::findCirclesGrid on the points: the grid's centres in OpenCV's row-major order of `layout`. A
// symmetric grid turned by about 90 deg is often found only as the transposed pattern (cols rows of rows
// dots): that order is taken transposed back (a mirror of the layout, which FindCircleGrid's handedness
// rule undoes).
bool FindWithOpenCv(const std::vector<cv::Point2f>& points, const CircleGridLayout& layout, std::vector<cv::Point2f>* centres,
                    std::string* error) {
  const int flags = layout.asymmetric ? cv::CALIB_CB_ASYMMETRIC_GRID : cv::CALIB_CB_SYMMETRIC_GRID;
  const size_t n = static_cast<size_t>(layout.size());
  try {
    if (cv::findCirclesGrid(points, cv::Size(layout.cols, layout.rows), *centres, flags, cv::Ptr<cv::FeatureDetector>(),
                            cv::CirclesGridFinderParameters()) &&
        centres->size() == n) {
      return true;
    }
    std::vector<cv::Point2f> transposed;
    if (layout.asymmetric || layout.rows == layout.cols ||
        !cv::findCirclesGrid(points, cv::Size(layout.rows, layout.cols), transposed, flags, cv::Ptr<cv::FeatureDetector>(),
                             cv::CirclesGridFinderParameters()) ||
        transposed.size() != n) {
      return false;
    }
    centres->resize(n);
    for (int r = 0; r < layout.rows; ++r) {
      for (int c = 0; c < layout.cols; ++c) (*centres)[static_cast<size_t>(r * layout.cols + c)] = transposed[static_cast<size_t>(c * layout.rows + r)];
    }
    return true;
  } catch (const cv::Exception& e) {
    *error = std::string("OpenCV's findCirclesGrid failed: ") + e.what();
    return false;
  }
}

}  // namespace

Eigen::Vector2d CircleGridLayout::Point(int id) const {
  const int r = id / cols, c = id % cols;
  return asymmetric ? Eigen::Vector2d(2 * c + r % 2, r) : Eigen::Vector2d(c, r);
}

std::vector<LayoutSymmetry> LayoutSymmetries(const CircleGridLayout& layout) {
  SELFCAL_CHECK(layout.rows >= 2 && layout.cols >= 2, "LayoutSymmetries: a grid of at least 2 x 2 dots");
  const int n = layout.size();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) centre += layout.Point(k);
  centre /= n;
  // Twice the coordinates about the centre are integers (the centre lies on a half step at worst).
  auto key = [](const Eigen::Vector2d& q) { return std::make_pair(std::lround(2 * q.x()), std::lround(2 * q.y())); };
  std::map<std::pair<long, long>, int> index;
  for (int k = 0; k < n; ++k) index[key(layout.Point(k) - centre)] = k;
  std::vector<LayoutSymmetry> out;
  for (int s = 0; s < 8; ++s) {
    // Rotation by s * 90 deg (s < 4), or that rotation after the mirror y -> -y (s >= 4).
    const double angle = (s % 4) * M_PI / 2;
    Eigen::Matrix2d m;
    m << std::lround(std::cos(angle)), -std::lround(std::sin(angle)), std::lround(std::sin(angle)), std::lround(std::cos(angle));
    if (s >= 4) m = m * Eigen::Vector2d(1, -1).asDiagonal();
    LayoutSymmetry sym;
    sym.rotation = s < 4;
    sym.angle_rad = sym.rotation ? angle : 0;
    for (int k = 0; k < n; ++k) {
      const auto it = index.find(key(m * (layout.Point(k) - centre)));
      if (it == index.end()) break;
      sym.perm.push_back(it->second);
    }
    if (static_cast<int>(sym.perm.size()) == n) out.push_back(std::move(sym));
  }
  return out;
}

CircleGridDetection FindCircleGrid(const std::vector<tracking::DotDetection>& dots, const CircleGridLayout& layout) {
  const std::vector<LayoutSymmetry> symmetries = LayoutSymmetries(layout);
  CircleGridDetection out;
  const int n = layout.size();
  if (static_cast<int>(dots.size()) < n) {
    out.message = "too few dots: " + std::to_string(dots.size()) + " found, the grid has " + std::to_string(n);
    return out;
  }
  std::vector<cv::Point2f> points;
  for (const tracking::DotDetection& d : dots) points.emplace_back(static_cast<float>(d.centroid_px.x()), static_cast<float>(d.centroid_px.y()));
  std::vector<cv::Point2f> centres;
  if (!FindWithOpenCv(points, layout, &centres, &out.message)) {
    if (out.message.empty()) {
      out.message = "no " + std::to_string(layout.rows) + " x " + std::to_string(layout.cols) +
                    (layout.asymmetric ? " asymmetric" : " symmetric") + " circle grid among " + std::to_string(dots.size()) + " dots";
    }
    return out;
  }
  // OpenCV's centres are the points handed in: back to the dots (and their unrounded centroids).
  std::vector<size_t> dot_of(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t d = 0; d < dots.size(); ++d) {
      const double e = (dots[d].centroid_px - Eigen::Vector2d(centres[static_cast<size_t>(k)].x, centres[static_cast<size_t>(k)].y)).norm();
      if (e < best) best = e, dot_of[static_cast<size_t>(k)] = d;
    }
    SELFCAL_CHECK(best < 0.01, "findCirclesGrid returned a centre that is none of the points handed to it");
  }
  // Every ordering the symmetries allow; then handedness, when mirrors allow either; then dot 0 top-left.
  std::vector<std::vector<size_t>> orderings;  // id -> dot index
  std::vector<double> dets;
  bool both_hands = false;
  for (const LayoutSymmetry& s : symmetries) {
    std::vector<size_t> o;
    std::vector<Eigen::Vector2d> px;
    for (int k = 0; k < n; ++k) {
      o.push_back(dot_of[static_cast<size_t>(s.perm[static_cast<size_t>(k)])]);
      px.push_back(dots[o.back()].centroid_px);
    }
    dets.push_back(AffineDeterminant(layout, px));
    both_hands = both_hands || !s.rotation;
    orderings.push_back(std::move(o));
  }
  size_t chosen = orderings.size();
  for (size_t o = 0; o < orderings.size(); ++o) {
    if (both_hands && !(dets[o] < 0)) continue;
    if (chosen == orderings.size() || dots[orderings[o][0]].centroid_px.sum() < dots[orderings[chosen][0]].centroid_px.sum()) {
      chosen = o;
    }
  }
  SELFCAL_CHECK(chosen < orderings.size(), "no ordering of the circle grid has the board's handedness");
  for (size_t d : orderings[chosen]) {
    out.centres_px.push_back(dots[d].centroid_px);
    out.contrast.push_back(dots[d].contrast);
  }
  out.found = true;
  std::ostringstream m;
  m << n << " dots on the " << (layout.asymmetric ? "asymmetric" : "symmetric") << " grid of " << dots.size() << " blobs";
  out.message = m.str();
  return out;
}

}  // namespace selfcal::detection
