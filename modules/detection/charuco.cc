#include "detection/charuco.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include "detection/corner_refine.h"

namespace selfcal::detection {

namespace {

// OpenCV's cv::aruco::PREDEFINED_DICTIONARY_NAME order: the name's index is the dictionary's number.
const std::vector<std::string> kDictionaryNames = {
    "DICT_4X4_50",  "DICT_4X4_100",  "DICT_4X4_250",  "DICT_4X4_1000",      "DICT_5X5_50",        "DICT_5X5_100",
    "DICT_5X5_250", "DICT_5X5_1000", "DICT_6X6_50",   "DICT_6X6_100",       "DICT_6X6_250",       "DICT_6X6_1000",
    "DICT_7X7_50",  "DICT_7X7_100",  "DICT_7X7_250",  "DICT_7X7_1000",      "DICT_ARUCO_ORIGINAL", "DICT_APRILTAG_16h5",
    "DICT_APRILTAG_25h9", "DICT_APRILTAG_36h10", "DICT_APRILTAG_36h11"};

int DictionaryIndex(const std::string& name) {
  const auto it = std::find(kDictionaryNames.begin(), kDictionaryNames.end(), name);
  return it == kDictionaryNames.end() ? -1 : static_cast<int>(it - kDictionaryNames.begin());
}

// A found marker: its board centre (squares) and image centre and corners (px).
struct FoundMarker {
  Eigen::Vector2d board = Eigen::Vector2d::Zero();
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> corners_px;
};

// The intersection of the quadrilateral's diagonals 0-2 and 1-3: the image of the square's centre.
Eigen::Vector2d DiagonalsMeet(const std::vector<cv::Point2f>& c) {
  const Eigen::Vector3d a(c[0].x, c[0].y, 1), b(c[2].x, c[2].y, 1), d(c[1].x, c[1].y, 1), e(c[3].x, c[3].y, 1);
  const Eigen::Vector3d x = a.cross(b).cross(d.cross(e));
  if (std::abs(x.z()) < 1e-12) return Eigen::Vector2d(0.25 * (c[0].x + c[1].x + c[2].x + c[3].x), 0.25 * (c[0].y + c[1].y + c[2].y + c[3].y));
  return x.head<2>() / x.z();
}

// The board's markers found in the image, by board marker index.
std::map<int, FoundMarker> FindMarkers(const cv::Mat& mat, const cv::Ptr<cv::aruco::CharucoBoard>& board) {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(mat, board->dictionary, corners, ids, cv::aruco::DetectorParameters::create());
  std::map<int, int> index_of_id;
  for (size_t k = 0; k < board->ids.size(); ++k) index_of_id[board->ids[k]] = static_cast<int>(k);
  std::map<int, int> seen;
  for (int id : ids) ++seen[id];
  std::map<int, FoundMarker> out;
  for (size_t k = 0; k < ids.size(); ++k) {
    const auto it = index_of_id.find(ids[k]);
    if (it == index_of_id.end() || seen[ids[k]] != 1) continue;  // not on the board, or found twice
    FoundMarker m;
    for (const cv::Point3f& p : board->objPoints[static_cast<size_t>(it->second)]) m.board += Eigen::Vector2d(p.x, p.y) / 4;
    m.centre_px = DiagonalsMeet(corners[k]);
    for (const cv::Point2f& p : corners[k]) m.corners_px.emplace_back(p.x, p.y);
    out[it->second] = std::move(m);
  }
  return out;
}

// The small and the large window's corners farther apart than this: something else lies in the large one.
// On the kvasios images the two agree within 1.2 px at every clean corner; a drawn axis line over a corner
// pulls them 6 px apart.
constexpr double kMaxDisagreementPx = 1.5;


// Step 2 and 3 for one inner corner at board position `x` (squares); false when it is not predicted or
// not refined.
bool FindCorner(const vpImage<unsigned char>& image, const std::map<int, FoundMarker>& markers, const Eigen::Vector2d& x,
                double min_radius_px, bool* predicted, Eigen::Vector2d* corner_px) {
  std::vector<cv::Point2f> from, to;
  std::vector<const FoundMarker*> neighbours;
  for (const auto& [index, m] : markers) {
    const double d = (m.board - x).norm();
    if (d > 2.5) continue;
    from.emplace_back(static_cast<float>(m.board.x()), static_cast<float>(m.board.y()));
    to.emplace_back(static_cast<float>(m.centre_px.x()), static_cast<float>(m.centre_px.y()));
    if (d < 0.75) neighbours.push_back(&m);
  }
  *predicted = false;
  if (neighbours.empty() || from.size() < 4) return false;
  const cv::Mat h = cv::findHomography(from, to, 0);
  if (h.empty()) return false;
  const Eigen::Matrix3d hm = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(h.ptr<double>());
  const Eigen::Vector3d q = hm * Eigen::Vector3d(x.x(), x.y(), 1);
  if (!(std::abs(q.z()) > 1e-12)) return false;
  const Eigen::Vector2d guess = q.head<2>() / q.z();
  *predicted = true;
  // The square's side in the image: the homography's image of a square's diagonal through the corner.
  auto map = [&](const Eigen::Vector2d& b) {
    const Eigen::Vector3d a = hm * Eigen::Vector3d(b.x(), b.y(), 1);
    return Eigen::Vector2d(a.head<2>() / a.z());
  };
  const double square_px = (map(x + Eigen::Vector2d(0.5, 0.5)) - map(x - Eigen::Vector2d(0.5, 0.5))).norm() / std::sqrt(2.0);
  double clear_px = std::numeric_limits<double>::infinity();
  for (const FoundMarker* m : neighbours) {
    for (const Eigen::Vector2d& c : m->corners_px) clear_px = std::min(clear_px, (c - guess).norm());
  }
  CornerRefineOptions ro;
  // The edges' directions: the homography's derivatives along the board's x and y at the corner.
  for (const Eigen::Vector3d& step : {Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(0, 0.01, 0)}) {
    const Eigen::Vector3d a = hm * (Eigen::Vector3d(x.x(), x.y(), 1) + step);
    ro.edge_directions_px.push_back((a.head<2>() / a.z() - guess).normalized());
  }
  // The band stays clear of the markers: their borders run parallel to the edges, clear / sqrt(2) away,
  // less the reach of the smoothing and the gradient kernel.
  ro.band_px = std::clamp(clear_px / std::sqrt(2.0) - 1.5 - 2 * ro.smoothing_sigma_px, 1.0, 3.0);
  ro.radius_px = 0.45 * square_px;
  if (!(ro.radius_px >= min_radius_px)) return false;
  const CheckedCorner r = RefineCornerChecked(image, guess, ro, kMaxDisagreementPx);
  if (!r.agree || (r.large.px - guess).norm() > 0.2 * square_px) return false;
  *corner_px = r.large.px;
  return true;
}

}  // namespace

const std::vector<std::string>& CharucoDictionaryNames() { return kDictionaryNames; }

Result<int> CharucoDictionarySize(const std::string& name) {
  const int index = DictionaryIndex(name);
  if (index < 0) {
    std::string names;
    for (const std::string& n : kDictionaryNames) names += (names.empty() ? "" : ", ") + n;
    return Status::Error(ErrorCode::kInvalidInput, "unknown ChArUco dictionary `" + name + "`: one of " + names);
  }
  return cv::aruco::getPredefinedDictionary(index)->bytesList.rows;
}

Status CharucoOptions::Validate() const {
  std::ostringstream s;
  const Result<int> size = CharucoDictionarySize(dictionary);
  if (!size.ok()) s << size.status().message() << "\n";
  if (rows < 2 || cols < 2 || rows > 100 || cols > 100) {
    s << "a ChArUco board needs at least 2 x 2 (and at most 100 x 100) squares, got " << rows << " x " << cols << "\n";
  } else if (size.ok() && rows * cols / 2 > *size) {
    s << "a " << rows << " x " << cols << " ChArUco board holds " << rows * cols / 2 << " markers, more than the "
      << *size << " of " << dictionary << "\n";
  }
  if (!(min_radius_px >= 1.5)) s << "min_radius_px must be >= 1.5, got " << min_radius_px << "\n";
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

CharucoDetection DetectCharuco(const vpImage<unsigned char>& image, const CharucoOptions& options) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid CharucoOptions:\n" << valid.message());
  SELFCAL_CHECK(image.getWidth() > 0 && image.getHeight() > 0, "DetectCharuco: empty image");
  const cv::Mat mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1,
                    const_cast<unsigned char*>(image.bitmap));
  // Square side 1 (positions in squares); the marker side only places the markers' corners, unused.
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      options.cols, options.rows, 1.0f, 0.5f, cv::aruco::getPredefinedDictionary(DictionaryIndex(options.dictionary)));
  const std::map<int, FoundMarker> markers = FindMarkers(mat, board);
  CharucoDetection out;
  out.markers = static_cast<int>(markers.size());
  for (size_t id = 0; id < board->chessboardCorners.size(); ++id) {
    const cv::Point3f& c = board->chessboardCorners[id];
    bool predicted = false;
    Eigen::Vector2d px;
    if (FindCorner(image, markers, Eigen::Vector2d(c.x, c.y), options.min_radius_px, &predicted, &px)) {
      out.corners_px[static_cast<int>(id)] = px;
    }
    out.predicted += predicted ? 1 : 0;
  }
  out.found = !out.corners_px.empty();
  std::ostringstream m;
  m << out.corners_px.size() << " of " << board->chessboardCorners.size() << " corners (" << out.markers << " markers, "
    << out.predicted - static_cast<int>(out.corners_px.size()) << " predicted corners not refined)";
  out.message = out.found ? m.str() : "no ChArUco corner found (" + std::to_string(out.markers) + " board markers)";
  return out;
}

}  // namespace selfcal::detection
