// Sub-pixel refinement of a chessboard corner (an X-junction of two dark and two light squares), shared by
// the chessboard and the ChArUco detectors.
//
// Method: Förstner's gradient orthogonality, as cv::cornerSubPix: at a corner p every image gradient g(q)
// near p is orthogonal to q - p (on the edges through p the gradient is across the edge, in the flat
// squares it is zero), so p is the least-squares point of sum_q w(q - p) (g(q)^T (q - p))^2, solved in
// closed form and iterated with the window re-centred on the new p. What differs from cv::cornerSubPix,
// each measured on rendered boards (sim/board_renderer.h, docs/detect.md "Corner precision"):
//   - the image is smoothed by a small Gaussian first (smoothing_sigma_px), so that the samples at
//     q = p + (dx, dy), interpolated bilinearly between pixels, follow the edges (an edge sharper than a
//     pixel is interpolated unevenly, differently on either side of the corner: cornerSubPix's 0.05 px
//     floor on a noise-free board);
//   - gradients by Scharr's kernels, whose direction is isotropic on sharp edges (central differences lean
//     towards the axes);
//   - the window: either a disc (weights exp(-r^2 / radius^2), as cornerSubPix's), or, given the corner's
//     two edge directions, the pixels within band_px of the two lines through p (weight 1, falling to 0
//     over one more pixel) out to radius_px: the edges carry the position, and so the window reaches
//     along them to nearly half a square without taking in what lies inside the squares (a ChArUco
//     marker a few pixels from the edge, whose border biases a large square window).
// Pixels as tracking/dot_detector.h (origin at the centre of the top-left pixel).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

namespace selfcal::detection {

struct CornerRefineOptions {
  double radius_px = 5;      // the disc of pixels used, >= 1.5
  int max_iterations = 100;
  double epsilon_px = 1e-4;  // stop when a step is shorter
  // The image smoothed by a Gaussian of this sigma first (0: not smoothed).
  double smoothing_sigma_px = 0.7;
  // When given (unit vectors in the image, the corner's two edges' directions): the band window above.
  std::vector<Eigen::Vector2d> edge_directions_px;
  double band_px = 3;
};

struct RefinedCorner {
  bool ok = false;               // converged inside the image, within radius_px of the start
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  int iterations = 0;
};

// The corner near `start` refined twice: on a disc of radius 3 px without a band (close to cv::cornerSubPix
// with a 7 x 7 window), and with `options`. `agree` when both converged within max_disagreement_px of each
// other: a line drawn across the board, a cable or a reflection inside the large window but outside the
// small one pulls the two apart. `large` and `small` are the two results.
struct CheckedCorner {
  bool agree = false;
  RefinedCorner large, small;
};
CheckedCorner RefineCornerChecked(const vpImage<unsigned char>& image, const Eigen::Vector2d& start,
                                  const CornerRefineOptions& options, double max_disagreement_px);

// The corner near `start`. Not ok when the window leaves the image, the normal equations are singular (no
// two edge directions in the window), the iterations do not converge, or the corner moved farther than
// radius_px from `start`. Throws InvalidArgument when radius_px < 1.5.
RefinedCorner RefineCorner(const vpImage<unsigned char>& image, const Eigen::Vector2d& start,
                           const CornerRefineOptions& options);

}  // namespace selfcal::detection
