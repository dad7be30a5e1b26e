// Corner precision on rendered boards with known corners (sim/board_renderer.h): selfcal's ChArUco and
// chessboard detectors (detection/charuco.h, detection/chessboard.h, refined by detection/corner_refine.h)
// against the true corners, beside cv::cornerSubPix with a 7 x 7 window (winSize 3) started at the same
// place. The camera: the kvasios RealSense's factory intrinsics and lens (1280 x 720); boards 0.3-0.6 m
// away, tilted up to 45 deg, blurred by 0.7 px, paper 210 and ink 40 grey levels.
//
// Tolerances. Bias: the mean error over every corner of every board below 0.02 px per axis noise-free and
// 0.05 px with noise. Noise: the Cramér-Rao bound of a corner's position from the noise-free image's
// gradients over the pixels the refinement uses, within the band along the corner's two edges (1.5 px for
// the chessboard detector, about 2 px for the ChArUco detector) out to 0.45 square (CornerBoundVariance):
// Fisher information F = sum_q grad I(q) grad I(q)^T / sigma^2, the bound's RMS per axis
// sqrt(trace(F^-1) / 2). Gradient orthogonality is not the maximum-likelihood fit (it smooths, and weighs
// every pixel of the band alike): its noise measured 2.8 to 3.7 times the bound, so the test allows 4:
// RMS error^2 <= floor^2 + (4 bound)^2, floor the noise-free RMS error. cornerSubPix 7x7 for comparison:
// 1.8 to 2.9 times selfcal's error on these boards.
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "detection/charuco.h"
#include "detection/charuco_pattern.h"
#include "detection/chessboard.h"
#include "sim/board_renderer.h"

namespace selfcal {
namespace {

CameraIntrinsics RealSense() {
  CameraIntrinsics c;
  c.width_px = 1280;
  c.height_px = 720;
  c.fx_px = 633.8876342773438;
  c.mu = 633.3662109375 / 633.8876342773438;
  c.cx_px = 641.9505615234375;
  c.cy_px = 358.99456787109375;
  c.k1 = -0.06063492223620415;
  c.k2 = 0.07267043739557266;
  c.p1 = -0.000246976938797161;
  c.p2 = 0.0005311704007908702;
  c.k3 = -0.02355414256453514;
  return c;
}

// The board's centre 0.3-0.6 m in front near the optical axis, tilted up to 45 deg, turned at random.
Rigid3 RandomPose(std::mt19937_64* rng, const Eigen::Vector2d& board_centre_m) {
  std::uniform_real_distribution<double> unit(0, 1);
  const double depth = 0.3 + 0.3 * unit(*rng), tilt = DegToRad(45) * unit(*rng), tilt_dir = 2 * M_PI * unit(*rng);
  const double spin = 2 * M_PI * unit(*rng);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(tilt_dir), std::sin(tilt_dir), 0)).toRotationMatrix() *
      Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d centre_in_cam(0.03 * (2 * unit(*rng) - 1), 0.02 * (2 * unit(*rng) - 1), depth);
  return Rigid3(r, centre_in_cam - r * Eigen::Vector3d(board_centre_m.x(), board_centre_m.y(), 0));
}

cv::Mat AsMat(const vpImage<unsigned char>& image) {
  return cv::Mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1, image.bitmap);
}

// The Cramér-Rao bound's variance (px^2, both axes summed) of a corner at `p` in the noise-free `image` with
// pixel noise sigma: trace(F^-1), F over the pixels within band_px of the corner's two edges (unit
// directions `edges`) and radius_px of it: the pixels that carry the corner's own position (a ChArUco
// marker's border moves with the board too, but the corner refinement stays clear of it).
double CornerBoundVariance(const vpImage<unsigned char>& image, const Eigen::Vector2d& p, const Eigen::Vector2d edges[2],
                           double radius_px, double band_px, double sigma) {
  Eigen::Matrix2d f = Eigen::Matrix2d::Zero();
  const int n = static_cast<int>(std::ceil(radius_px));
  const int u0 = static_cast<int>(std::lround(p.x())), v0 = static_cast<int>(std::lround(p.y()));
  for (int v = v0 - n; v <= v0 + n; ++v) {
    for (int u = u0 - n; u <= u0 + n; ++u) {
      const Eigen::Vector2d d = Eigen::Vector2d(u, v) - p;
      const double across = std::min(std::abs(edges[0].x() * d.y() - edges[0].y() * d.x()),
                                     std::abs(edges[1].x() * d.y() - edges[1].y() * d.x()));
      if (d.norm() > radius_px || across > band_px) continue;
      const Eigen::Vector2d g(0.5 * (image[static_cast<unsigned>(v)][u + 1] - image[static_cast<unsigned>(v)][u - 1]),
                              0.5 * (image[static_cast<unsigned>(v + 1)][u] - image[static_cast<unsigned>(v - 1)][u]));
      f += g * g.transpose() / (sigma * sigma);
    }
  }
  return f.inverse().trace();
}

struct Errors {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double sum2 = 0, bound2 = 0;
  int n = 0;
  void Add(const Eigen::Vector2d& e) {
    sum += e;
    sum2 += e.squaredNorm();
    ++n;
  }
  Eigen::Vector2d Mean() const { return sum / n; }
  double RmsPerAxis() const { return std::sqrt(sum2 / n / 2); }
  double BoundPerAxis() const { return std::sqrt(bound2 / n / 2); }
};

struct Measured {
  Errors selfcal, subpix;
};

// `boards` rendered boards with noise `noise_grey`, the bound over a band of band_px (the detector's):
// selfcal's corners (by `detect`: id -> px of one image,
// given the true corners by id)
// and cornerSubPix 7x7's from the same start as the truth displaced by 0.7 px, against the truth.
template <typename Detect>
Measured Measure(const sim::BoardTexture& texture, const std::vector<Eigen::Vector3d>& corners_m, const Eigen::Vector2d& centre_m,
                 double square_m, int boards, double noise_grey, double band_px, const Detect& detect) {
  const CameraIntrinsics camera = RealSense();
  const sim::BoardRenderer renderer(camera);
  std::mt19937_64 rng(7);
  Measured out;
  for (int b = 0; b < boards; ++b) {
    const Rigid3 cam_from_board = RandomPose(&rng, centre_m);
    sim::BoardRenderOptions ro;
    ro.off_plane_grey = 90;
    ro.blur_sigma_px = 0.7;
    const vpImage<unsigned char> clean = renderer.Render(cam_from_board, texture, ro);
    ro.noise_std_grey = noise_grey;
    ro.noise_seed = 100 + static_cast<uint64_t>(b);
    const vpImage<unsigned char> image = renderer.Render(cam_from_board, texture, ro);
    std::map<int, Eigen::Vector2d> truth_px;
    for (size_t id = 0; id < corners_m.size(); ++id) truth_px[static_cast<int>(id)] = *Project(camera, cam_from_board * corners_m[id]);
    const std::map<int, Eigen::Vector2d> found = detect(image, truth_px);
    std::vector<cv::Point2f> start;
    std::vector<Eigen::Vector2d> truth;
    for (const auto& [id, px] : found) {
      const Eigen::Vector2d t = *Project(camera, cam_from_board * corners_m[static_cast<size_t>(id)]);
      out.selfcal.Add(px - t);
      truth.push_back(t);
      start.emplace_back(static_cast<float>(t.x() + 0.5), static_cast<float>(t.y() - 0.5));
      if (noise_grey > 0) {
        // The square's side in the image near the corner: the disc the bound is taken over.
        const Eigen::Vector3d x = corners_m[static_cast<size_t>(id)];
        const Eigen::Vector2d along_x = *Project(camera, cam_from_board * (x + Eigen::Vector3d(square_m, 0, 0))) - t;
        const Eigen::Vector2d along_y = *Project(camera, cam_from_board * (x + Eigen::Vector3d(0, square_m, 0))) - t;
        const Eigen::Vector2d edges[2] = {along_x.normalized(), along_y.normalized()};
        out.selfcal.bound2 += CornerBoundVariance(clean, t, edges, 0.45 * std::min(along_x.norm(), along_y.norm()), band_px, noise_grey);
      }
    }
    if (start.empty()) continue;
    cv::cornerSubPix(AsMat(image), start, cv::Size(3, 3), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    for (size_t k = 0; k < start.size(); ++k) out.subpix.Add(Eigen::Vector2d(start[k].x, start[k].y) - truth[k]);
  }
  return out;
}

void Report(const char* what, const Measured& m) {
  std::printf("%s: %d corners, selfcal RMS/axis %.4f px mean (%+.4f, %+.4f), bound %.4f; cornerSubPix 7x7 RMS/axis %.4f\n",
              what, m.selfcal.n, m.selfcal.RmsPerAxis(), m.selfcal.Mean().x(), m.selfcal.Mean().y(),
              m.selfcal.BoundPerAxis(), m.subpix.RmsPerAxis());
}

void ExpectAtTheNoiseLimit(const Measured& clean, const Measured& noisy, int min_corners) {
  ASSERT_GE(clean.selfcal.n, min_corners);
  ASSERT_GE(noisy.selfcal.n, min_corners);
  EXPECT_LT(clean.selfcal.Mean().cwiseAbs().maxCoeff(), 0.02);
  EXPECT_LT(noisy.selfcal.Mean().cwiseAbs().maxCoeff(), 0.05);
  const double floor = clean.selfcal.RmsPerAxis(), bound = noisy.selfcal.BoundPerAxis();
  EXPECT_LT(noisy.selfcal.RmsPerAxis(), std::sqrt(floor * floor + 16 * bound * bound));
  // At least as good as cornerSubPix 7x7, which is started at the true corner's neighbourhood.
  EXPECT_LT(clean.selfcal.RmsPerAxis(), clean.subpix.RmsPerAxis());
  EXPECT_LT(noisy.selfcal.RmsPerAxis(), noisy.subpix.RmsPerAxis());
}

// The chessboard detector's corners, each named by the true corner nearest it (within 3 px): the ordering's
// cues are the detector's business (chessboard_test.cc).
auto ChessboardByNearestTruth(const detection::ChessboardOptions& options) {
  return [options](const vpImage<unsigned char>& image, const std::map<int, Eigen::Vector2d>& truth) {
    std::map<int, Eigen::Vector2d> out;
    for (const Eigen::Vector2d& p : detection::DetectChessboard(image, options, {}).corners_px) {
      for (const auto& [id, t] : truth) {
        if ((p - t).norm() < 3) out[id] = p;
      }
    }
    return out;
  };
}

detection::CharucoOptions KvasiosBoard() {
  detection::CharucoOptions o;
  o.dictionary = "DICT_6X6_250";
  o.cols = 5;
  o.rows = 7;
  return o;
}

TEST(CornerPrecision, CharucoCornersAreUnbiasedAndAtTheNoiseLimitOnRenderedBoards) {
  const detection::CharucoOptions options = KvasiosBoard();
  const detection::CharucoPattern pattern(options, 0.034, 0.028);
  const sim::BoardTexture texture = [&](double x, double y) { return pattern.DarkAt(x, y) ? 40.0 : 210.0; };
  auto detect = [&](const vpImage<unsigned char>& image, const std::map<int, Eigen::Vector2d>&) {
    return detection::DetectCharuco(image, options).corners_px;
  };
  const Eigen::Vector2d centre(0.5 * 5 * 0.034, 0.5 * 7 * 0.034);
  const Measured clean = Measure(texture, pattern.corners_m(), centre, 0.034, 12, 0, 2.0, detect);
  const Measured noisy = Measure(texture, pattern.corners_m(), centre, 0.034, 12, 2.0, 2.0, detect);
  Report("charuco, noise-free", clean);
  Report("charuco, noise 2 grey", noisy);
  ExpectAtTheNoiseLimit(clean, noisy, 12 * 20);
}

TEST(CornerPrecision, ChessboardCornersAreUnbiasedAndAtTheNoiseLimitOnRenderedBoards) {
  // 7 x 10 squares of 25 mm: 6 x 9 inner corners, as the ViSP set's board.
  const sim::BoardTexture texture = sim::ChessboardTexture(7, 10, 0.025, 40, 210);
  std::vector<Eigen::Vector3d> corners_m;
  for (int r = 1; r <= 6; ++r) {
    for (int c = 1; c <= 9; ++c) corners_m.emplace_back(c * 0.025, r * 0.025, 0);
  }
  detection::ChessboardOptions options;
  options.rows = 6;
  options.cols = 9;
  const auto detect = ChessboardByNearestTruth(options);
  const Eigen::Vector2d centre(0.125, 0.0875);
  const Measured clean = Measure(texture, corners_m, centre, 0.025, 12, 0, 1.5, detect);
  const Measured noisy = Measure(texture, corners_m, centre, 0.025, 12, 2.0, 1.5, detect);
  Report("chessboard, noise-free", clean);
  Report("chessboard, noise 2 grey", noisy);
  ExpectAtTheNoiseLimit(clean, noisy, 12 * 54);
}

// The chessboard detector on a ChArUco board (it sees the inner corners, not the markers): the markers'
// borders a few pixels beside the edges must not pull its corners (cv::cornerSubPix with a window of 0.4
// times the corner spacing, the refinement before, fitted such boards worse than a 7 x 7 window).
TEST(CornerPrecision, ChessboardCornersOfACharucoBoardAreNotPulledByTheMarkers) {
  const detection::CharucoPattern pattern(KvasiosBoard(), 0.034, 0.028);
  const sim::BoardTexture texture = [&](double x, double y) { return pattern.DarkAt(x, y) ? 40.0 : 210.0; };
  detection::ChessboardOptions options;
  options.rows = 6;  // the 4 x 6 inner corners in whichever order: named by the nearest true corner
  options.cols = 4;
  const auto detect = ChessboardByNearestTruth(options);
  const Eigen::Vector2d centre(0.5 * 5 * 0.034, 0.5 * 7 * 0.034);
  // 8 boards: on a few of the first 12 cv::findChessboardCorners takes tens of seconds (the markers are squares
  // too).
  const Measured clean = Measure(texture, pattern.corners_m(), centre, 0.034, 8, 0, 1.5, detect);
  const Measured noisy = Measure(texture, pattern.corners_m(), centre, 0.034, 8, 2.0, 1.5, detect);
  Report("chessboard on charuco, noise-free", clean);
  Report("chessboard on charuco, noise 2 grey", noisy);
  ExpectAtTheNoiseLimit(clean, noisy, 8 * 20);
}

}  // namespace
}  // namespace selfcal
