// The board renderer's geometry and pixel convention, checked on pixels whose coverage is known in closed
// form: a fronto-parallel chessboard through a pinhole camera, each square's edges at known sub-pixel
// positions.
#include <cmath>

#include <gtest/gtest.h>

#include "base/status.h"
#include "sim/board_renderer.h"

namespace selfcal::sim {
namespace {

CameraIntrinsics Pinhole() {
  CameraIntrinsics c;
  c.width_px = 200;
  c.height_px = 160;
  c.fx_px = 500;
  c.cx_px = 99.5;
  c.cy_px = 79.5;
  return c;
}

// The board 1 m in front, its x and y along u and v: a board point (x, y) projects to
// (cx + 500 (x + ox), cy + 500 (y + oy)); squares of 20 mm are 10 px.
Rigid3 FrontoParallel(double ox_m, double oy_m) { return Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(ox_m, oy_m, 1.0)); }

TEST(BoardRenderer, APixelTakesTheShareOfItsAreaEachSquareCovers) {
  const CameraIntrinsics camera = Pinhole();
  const BoardRenderer renderer(camera);
  BoardRenderOptions o;
  o.supersampling = 16;
  // Board origin at u = 99.5 + 500 * (-0.0403) = 79.35, v = 79.5 + 500 * (-0.0203) = 69.35: the squares' edges
  // at u = 79.35 + 10 k and v = 69.35 + 10 k.
  const vpImage<unsigned char> image =
      renderer.Render(FrontoParallel(-0.0403, -0.0203), ChessboardTexture(4, 6, 0.02, 40, 210), o);
  // Inside square (0, 0), dark; inside square (0, 1), light; off the board, the paper.
  EXPECT_EQ(image[74][84], 40);
  EXPECT_EQ(image[74][94], 210);
  EXPECT_EQ(image[10][10], 210);
  // Pixel u = 89 covers [88.5, 89.5]; the edge between squares (0, 0) and (0, 1) at u = 89.35: 0.85 of it
  // dark. Pixel u = 79 covers [78.5, 79.5], the board's left edge at 79.35: 0.15 dark.
  // Within the rounding to a grey level and the 1 / 256 of the samples (0.7 grey levels).
  EXPECT_NEAR(image[74][89], 0.85 * 40 + 0.15 * 210, 1.2);
  EXPECT_NEAR(image[74][79], 0.15 * 40 + 0.85 * 210, 1.2);
  // The corner pixel (89, 79) at the corner u = 89.35, v = 79.35 of four squares: dark shares
  // 0.85 * 0.85 (square (0, 0)) + 0.15 * 0.15 (square (1, 1)).
  const double dark = 0.85 * 0.85 + 0.15 * 0.15;
  // A rotated grid resolves a region bounded along both u and v only to ~1 / S of the pixel (the samples'
  // lattice): 170 / 16 grey levels (measured 4.4).
  EXPECT_NEAR(image[79][89], dark * 40 + (1 - dark) * 210, 170.0 / 16);
}

TEST(BoardRenderer, NoiseIsSeededAndBlurKeepsTheMean) {
  const BoardRenderer renderer(Pinhole());
  const BoardTexture flat = [](double, double) { return 120.0; };
  BoardRenderOptions o;
  o.noise_std_grey = 3;
  o.noise_seed = 5;
  const vpImage<unsigned char> a = renderer.Render(FrontoParallel(0, 0), flat, o);
  const vpImage<unsigned char> b = renderer.Render(FrontoParallel(0, 0), flat, o);
  double sum = 0, sum2 = 0;
  bool same = true;
  for (unsigned v = 0; v < a.getHeight(); ++v) {
    for (unsigned u = 0; u < a.getWidth(); ++u) {
      same = same && a[v][u] == b[v][u];
      sum += a[v][u] - 120.0;
      sum2 += (a[v][u] - 120.0) * (a[v][u] - 120.0);
    }
  }
  const double n = a.getWidth() * a.getHeight();
  EXPECT_TRUE(same);
  EXPECT_NEAR(sum / n, 0, 0.05);
  EXPECT_NEAR(std::sqrt(sum2 / n), std::sqrt(9 + 1.0 / 12), 0.1);  // the noise and the rounding
  o.noise_std_grey = 0;
  o.blur_sigma_px = 1.5;
  const vpImage<unsigned char> blurred = renderer.Render(FrontoParallel(0, 0), flat, o);
  EXPECT_EQ(blurred[80][100], 120);
  o.supersampling = 0;
  EXPECT_THROW(renderer.Render(FrontoParallel(0, 0), flat, o), InvalidArgument);
}

}  // namespace
}  // namespace selfcal::sim
