// The printed pattern of a ChArUco board with its metric geometry, as OpenCV 4.6's cv::aruco::CharucoBoard
// lays it out: the reference that detection/charuco.h is measured against (test boards rendered through
// sim/board_renderer.h, the corners' known positions for a camera pose fit). Not used to detect: the
// detector needs no square or marker length.
//
// Board frame: OpenCV's, metres: x along the columns, y along the rows (down the printed image, as OpenCV 4.6
// draws it), z = 0 the board, the printed face seen unmirrored from the side of -z; squares
// [c s, (c + 1) s] x [r s, (r + 1) s] for r < rows, c < cols. The squares without a marker are dark; a
// marker square is light around its marker (side marker_m, centred), whose cells ((bits + 2) x (bits + 2):
// a one-cell dark border around the dictionary's bits) are dark or light. Outside the squares: light.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "detection/charuco.h"

namespace selfcal::detection {

class CharucoPattern {
 public:
  // Throws InvalidArgument on invalid options or lengths (0 < marker_m < square_m).
  CharucoPattern(const CharucoOptions& options, double square_m, double marker_m);

  // The inner corners by id (OpenCV's ChArUco ids), board frame, z = 0.
  const std::vector<Eigen::Vector3d>& corners_m() const { return corners_m_; }
  // Whether the board point (x, y) is printed dark.
  bool DarkAt(double x_m, double y_m) const;

 private:
  struct Marker {
    Eigen::Vector2d origin, u_axis, v_axis;  // corner 0 and the unit directions to corners 1 and 3
    std::vector<unsigned char> light;        // cells row-major, (bits + 2)^2, 1 = light
  };
  int rows_, cols_, cells_ = 0;
  double square_m_, marker_m_;
  std::vector<int> marker_of_square_;  // r * cols + c -> index into markers_, -1 for a dark square
  std::vector<Marker> markers_;
  std::vector<Eigen::Vector3d> corners_m_;
};

}  // namespace selfcal::detection
