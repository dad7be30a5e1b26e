// Renders a flat printed board (a chessboard, a ChArUco board, any pattern given as a grey level at each
// point of the board) as the camera sees it, with the corners' truth known exactly: the test image of
// corner detectors (detection/corner_refine.h), the way image_renderer.h renders dots.
//
// Geometry. The board is the plane z = 0 of its frame; `grey_at(x, y)` gives the printed grey level at the
// board point (x, y) (metres), or any level for points off the board (the surround). A pixel (u, v) covers
// [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5] (camera/camera.h: pixel centres at integers). Its grey level is
// the mean of S x S samples (S = supersampling) on a rotated grid: sample (i, j) at
// ((i + (j + 0.5) / S) / S - 0.5, (j + (i + 0.5) / S) / S - 0.5) from the pixel's centre, every sample at a
// column and a row of its own, so that an edge along u or v is resolved to 1 / S^2 of the pixel, not 1 / S;
// each back-projected (every lens coefficient inverted: PixelToNormalized at the pixels' corners,
// computed once per camera, interpolated bilinearly inside the pixel, where the lens is smooth to ~1e-9 of a
// pixel), its ray intersected with the board's plane and the plane point's grey read; a ray that misses the plane (parallel
// or behind the camera) reads `off_plane_grey`. A pixel whose four corners and centre read the same level
// takes that level without supersampling (the pattern's features are far larger than a pixel). Then a
// Gaussian blur (sigma px, border replicated), additive Gaussian noise (sim/image_formation.h's
// GaussianNoise, seeded, row-major), rounding and clamping to [0, 255].
//
// Truth: a board point X projects to Project(camera, cam_from_board * X). A pixel's coverage by each
// colour is exact to the sampling: within 1 / S^2 of the pixel for an edge along u or v, ~1 / S at a
// corner's own pixel (board_renderer_test.cc); the errors of neighbouring pixels along an edge at any other
// angle average out.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <visp3/core/vpImage.h>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::sim {

struct BoardRenderOptions {
  int supersampling = 8;  // samples per pixel along each axis, 1..16
  double off_plane_grey = 0;
  double blur_sigma_px = 0;   // Gaussian, 0 = none
  double noise_std_grey = 0;  // additive Gaussian pixel noise, grey levels
  uint64_t noise_seed = 1;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

// The grey level printed at board point (x_m, y_m).
using BoardTexture = std::function<double(double x_m, double y_m)>;

class BoardRenderer {
 public:
  // Throws InvalidArgument on an invalid camera.
  explicit BoardRenderer(const CameraIntrinsics& camera);
  // The board seen from the camera at `cam_from_board`. Throws InvalidArgument on invalid options.
  vpImage<unsigned char> Render(const Rigid3& cam_from_board, const BoardTexture& grey_at,
                                const BoardRenderOptions& options) const;

 private:
  CameraIntrinsics camera_;
  std::vector<Eigen::Vector2d> corner_rays_;  // normalised (x, y) of pixel corner (i - 0.5, j - 0.5), row-major
};

// A plain chessboard texture: squares of side square_m, rows x cols squares from the board origin along
// +x (columns) and +y (rows), square (0, 0) dark; outside the squares the paper (light_grey).
BoardTexture ChessboardTexture(int rows, int cols, double square_m, double dark_grey, double light_grey);

// A circle grid board (OpenCV's layouts, no origin dot): rows x cols discs of radius radius_m, disc (r, c)
// centred at (c, r) * spacing_m, or at (2 c + r mod 2, r) * spacing_m when asymmetric; dot_grey on
// board_grey (light dots on a dark board, or dark on light) within margin_m of the outermost discs' centres,
// and outside the board `surround` (a table's texture), or board_grey where that is empty.
BoardTexture CircleGridTexture(int rows, int cols, bool asymmetric, double spacing_m, double radius_m, double dot_grey,
                               double board_grey, double margin_m, BoardTexture surround = nullptr);

}  // namespace selfcal::sim
