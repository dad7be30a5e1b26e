// Test-only: synthetic views of a chessboard and of a modified circle grid with known point ids, rendered
// with the tracking tests' supersampled renderer (tracking/tracking_test_util.h).
//
// Target units: one square (chessboard) or one dot spacing (grid). Point (row, col) is at (col, row); the
// printed target is seen from the front with +row going up the screen, so that its ids follow the
// handedness of grid_identity.h and chessboard.h. Chessboard squares: the square with lower corner (i, j),
// i in [-1, cols - 1], j in [-1, rows - 1], is dark when i + j is even, so the square between corners 0, 1,
// cols and cols + 1 is dark.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <visp3/core/vpImage.h>

#include "tracking/tracking_test_util.h"

namespace selfcal::detection::testing {

// image_from_target: the target centred in a 640 x 480 image, `px_per_unit` per unit, turned by
// roll_deg on screen, with some perspective.
inline Eigen::Matrix3d View(int rows, int cols, double roll_deg, double px_per_unit, double perspective = 1.0) {
  const double a = roll_deg * M_PI / 180;
  Eigen::Matrix3d flip;  // +row goes up the screen (-v)
  flip << 1, 0, 0, 0, -1, 0, 0, 0, 1;
  Eigen::Matrix3d rot;
  rot << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  Eigen::Matrix3d scale = Eigen::Matrix3d::Identity();
  scale(0, 0) = scale(1, 1) = px_per_unit;
  Eigen::Matrix3d persp = Eigen::Matrix3d::Identity();
  persp(2, 0) = 1.5e-4 * perspective;
  persp(2, 1) = -1.0e-4 * perspective;
  Eigen::Matrix3d centre = Eigen::Matrix3d::Identity();
  centre(0, 2) = 320;
  centre(1, 2) = 240;
  Eigen::Matrix3d to_middle = Eigen::Matrix3d::Identity();
  to_middle(0, 2) = -(cols - 1) / 2.0;
  to_middle(1, 2) = -(rows - 1) / 2.0;
  return centre * persp * rot * scale * flip * to_middle;
}

inline Eigen::Vector2d Project(const Eigen::Matrix3d& view, double x, double y) {
  return (view * Eigen::Vector3d(x, y, 1)).hnormalized();
}

// The true pixel of every point, by id = row * cols + col.
inline std::vector<Eigen::Vector2d> TruePoints(const Eigen::Matrix3d& view, int rows, int cols) {
  std::vector<Eigen::Vector2d> out;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) out.push_back(Project(view, c, r));
  }
  return out;
}

// A square [x0, x0 + 1] x [y0, y0 + 1] of the target seen through `view`.
inline tracking::testing::Shape ProjectedSquare(const Eigen::Matrix3d& view, double x0, double y0, double level) {
  const Eigen::Matrix3d inverse = view.inverse();
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (const auto& [dx, dy] : {std::pair{0, 0}, {1, 0}, {0, 1}, {1, 1}}) {
    const Eigen::Vector2d p = Project(view, x0 + dx, y0 + dy);
    u0 = std::min(u0, p.x());
    v0 = std::min(v0, p.y());
    u1 = std::max(u1, p.x());
    v1 = std::max(v1, p.y());
  }
  return tracking::testing::Shape{[=](double u, double v) {
                                    const Eigen::Vector2d q = (inverse * Eigen::Vector3d(u, v, 1)).hnormalized();
                                    return q.x() >= x0 && q.x() <= x0 + 1 && q.y() >= y0 && q.y() <= y0 + 1;
                                  },
                                  u0, v0, u1, v1, level};
}

// A chessboard of rows x cols inner corners on a white margin of one square.
inline vpImage<unsigned char> RenderChessboard(const Eigen::Matrix3d& view, int rows, int cols, double noise = 1.0,
                                               unsigned seed = 1) {
  std::vector<tracking::testing::Shape> shapes;
  for (int j = -1; j < rows; ++j) {
    for (int i = -1; i < cols; ++i) {
      if (((i + j) % 2 + 2) % 2 == 0) shapes.push_back(ProjectedSquare(view, i, j, 30));
    }
  }
  return tracking::testing::Render(640, 480, 225, shapes, 4, noise, seed);
}

// A modified circle grid: dots of radius 0.2, the origin's 0.4.
inline vpImage<unsigned char> RenderDotGrid(const Eigen::Matrix3d& view, int rows, int cols, double noise = 1.5,
                                            unsigned seed = 3) {
  std::vector<tracking::testing::Shape> shapes;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      shapes.push_back(tracking::testing::ProjectedDisc(view, Eigen::Vector2d(c, r), (r == 0 && c == 0) ? 0.4 : 0.2, 40));
    }
  }
  return tracking::testing::Render(640, 480, 210, shapes, 8, noise, seed);
}

}  // namespace selfcal::detection::testing
