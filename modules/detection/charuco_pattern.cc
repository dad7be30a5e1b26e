#include "detection/charuco_pattern.h"

#include <algorithm>
#include <cmath>

#include <opencv2/aruco/charuco.hpp>

namespace selfcal::detection {

CharucoPattern::CharucoPattern(const CharucoOptions& options, double square_m, double marker_m)
    : rows_(options.rows), cols_(options.cols), square_m_(square_m), marker_m_(marker_m) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid CharucoOptions:\n" << valid.message());
  SELFCAL_CHECK(marker_m > 0 && marker_m < square_m, "CharucoPattern: marker " << marker_m << " m, square " << square_m << " m");
  const std::vector<std::string>& names = CharucoDictionaryNames();
  const int dictionary_index = static_cast<int>(std::find(names.begin(), names.end(), options.dictionary) - names.begin());
  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(dictionary_index);
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      cols_, rows_, static_cast<float>(square_m), static_cast<float>(marker_m), dictionary);
  const int bits = dictionary->markerSize;
  cells_ = bits + 2;
  marker_of_square_.assign(static_cast<size_t>(rows_ * cols_), -1);
  for (size_t k = 0; k < board->ids.size(); ++k) {
    const std::vector<cv::Point3f>& c = board->objPoints[k];
    Marker m;
    m.origin = Eigen::Vector2d(c[0].x, c[0].y);
    m.u_axis = (Eigen::Vector2d(c[1].x, c[1].y) - m.origin).normalized();
    m.v_axis = (Eigen::Vector2d(c[3].x, c[3].y) - m.origin).normalized();
    cv::Mat code;
    cv::aruco::Dictionary::getBitsFromByteList(dictionary->bytesList.rowRange(board->ids[k], board->ids[k] + 1), bits)
        .copyTo(code);
    m.light.assign(static_cast<size_t>(cells_ * cells_), 0);
    for (int r = 0; r < bits; ++r) {
      for (int col = 0; col < bits; ++col) m.light[static_cast<size_t>((r + 1) * cells_ + col + 1)] = code.at<unsigned char>(r, col) != 0;
    }
    const Eigen::Vector2d centre = m.origin + 0.5 * marker_m * (m.u_axis + m.v_axis);
    const int sr = static_cast<int>(std::floor(centre.y() / square_m)), sc = static_cast<int>(std::floor(centre.x() / square_m));
    marker_of_square_[static_cast<size_t>(sr * cols_ + sc)] = static_cast<int>(markers_.size());
    markers_.push_back(std::move(m));
  }
  for (const cv::Point3f& p : board->chessboardCorners) corners_m_.emplace_back(p.x, p.y, 0.0);
}

bool CharucoPattern::DarkAt(double x_m, double y_m) const {
  const double sc = std::floor(x_m / square_m_), sr = std::floor(y_m / square_m_);
  if (sc < 0 || sr < 0 || sc >= cols_ || sr >= rows_) return false;
  const int index = marker_of_square_[static_cast<size_t>(static_cast<int>(sr) * cols_ + static_cast<int>(sc))];
  if (index < 0) return true;
  const Marker& m = markers_[static_cast<size_t>(index)];
  const Eigen::Vector2d d = Eigen::Vector2d(x_m, y_m) - m.origin;
  const double u = d.dot(m.u_axis) / marker_m_, v = d.dot(m.v_axis) / marker_m_;
  if (u < 0 || v < 0 || u >= 1 || v >= 1) return false;
  const int cu = static_cast<int>(u * cells_), cv_ = static_cast<int>(v * cells_);
  return m.light[static_cast<size_t>(cv_ * cells_ + cu)] == 0;
}

}  // namespace selfcal::detection
