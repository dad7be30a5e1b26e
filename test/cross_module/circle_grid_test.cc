// Dots of either polarity and circle grids without an origin dot (detection/blob_candidates.h,
// detection/circle_grid.h, detection/grid_orientation.h) on boards rendered with known dot centres
// (sim/board_renderer.h's CircleGridTexture): white dots on a black board, a textured table around it.
//
// Truth: each disc's projected area centroid (sim::EllipseCentrePx, exact for the pinhole camera used
// here), what an unbiased blob detector measures. Ids: each detected id is matched to the nearest true
// disc; the map detected id -> true disc must be one bijection for every image (one naming of the
// physical dots, up to the one symmetry the first image chose).
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "detection/circle_grid.h"
#include "detection/detect_points.h"
#include "detection/grid_orientation.h"
#include "sim/board_renderer.h"
#include "sim/image_renderer.h"

namespace selfcal {
namespace {

constexpr double kSpacingM = 0.01, kRadiusM = 0.0033;

CameraIntrinsics Pinhole() {
  CameraIntrinsics c;
  c.width_px = 1024;
  c.height_px = 768;
  c.fx_px = 1000;
  c.cx_px = 511.5;
  c.cy_px = 383.5;
  return c;
}

struct Board {
  detection::CircleGridLayout layout;
  Eigen::Vector3d Centre(int id) const {
    const Eigen::Vector2d l = layout.Point(id) * kSpacingM;
    return Eigen::Vector3d(l.x(), l.y(), 0);
  }
  Eigen::Vector2d Middle() const {
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    for (int k = 0; k < layout.size(); ++k) m += layout.Point(k) * kSpacingM;
    return m / layout.size();
  }
};

// A table of random round spots (radius 1-10 mm, any grey) on a wavy grain: blobs a dot detector accepts.
// The spots are bucketed in 2 cm cells (a spot lies in every cell its square overlaps) for speed.
sim::BoardTexture Table(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  constexpr double kCell = 0.02, kX0 = -0.15, kY0 = -0.15;
  constexpr int kCells = 25;
  std::vector<std::vector<Eigen::Vector4d>> cells(kCells * kCells);  // x, y, radius, grey
  for (int k = 0; k < 600; ++k) {
    const Eigen::Vector4d s(kX0 + 0.45 * u(rng), kY0 + 0.4 * u(rng), 0.001 + 0.009 * u(rng), 255 * u(rng));
    for (int i = static_cast<int>((s[0] - s[2] - kX0) / kCell); i <= static_cast<int>((s[0] + s[2] - kX0) / kCell); ++i) {
      for (int j = static_cast<int>((s[1] - s[2] - kY0) / kCell); j <= static_cast<int>((s[1] + s[2] - kY0) / kCell); ++j) {
        if (i >= 0 && j >= 0 && i < kCells && j < kCells) cells[static_cast<size_t>(j * kCells + i)].push_back(s);
      }
    }
  }
  return [cells](double x, double y) {
    const int i = static_cast<int>(std::floor((x - kX0) / kCell)), j = static_cast<int>(std::floor((y - kY0) / kCell));
    if (i >= 0 && j >= 0 && i < kCells && j < kCells) {
      for (const Eigen::Vector4d& s : cells[static_cast<size_t>(j * kCells + i)]) {
        if ((x - s[0]) * (x - s[0]) + (y - s[1]) * (y - s[1]) <= s[2] * s[2]) return s[3];
      }
    }
    return 150 + 40 * std::sin(180 * x + 25 * std::sin(60 * y));
  };
}

// The board's middle 0.3-0.45 m in front near the optical axis, tilted up to 30 deg, spun by `spin`.
Rigid3 CamFromBoard(std::mt19937_64* rng, const Board& board, double spin) {
  std::uniform_real_distribution<double> unit(0, 1);
  const double depth = 0.3 + 0.15 * unit(*rng), tilt = DegToRad(30) * unit(*rng), dir = 2 * M_PI * unit(*rng);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(dir), std::sin(dir), 0)).toRotationMatrix() *
                            Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d middle_in_cam(0.02 * (2 * unit(*rng) - 1), 0.02 * (2 * unit(*rng) - 1), depth);
  const Eigen::Vector2d m = board.Middle();
  return Rigid3(r, middle_in_cam - r * Eigen::Vector3d(m.x(), m.y(), 0));
}

struct Rendered {
  std::vector<vpImage<unsigned char>> images;
  std::vector<std::vector<Eigen::Vector2d>> truth_px;  // per image, per true disc
  std::vector<detection::ImageRobotPose> poses;        // flange poses
};

// Images of one board from cameras at the given spins; the flange poses through a hand-eye transform.
Rendered Render(const Board& board, const std::vector<double>& spins_deg, double dot_grey, double board_grey,
                const sim::BoardTexture& table, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const CameraIntrinsics camera = Pinhole();
  const sim::BoardRenderer renderer(camera);
  const sim::BoardTexture texture = sim::CircleGridTexture(board.layout.rows, board.layout.cols, board.layout.asymmetric,
                                                           kSpacingM, kRadiusM, dot_grey, board_grey, 0.012, table);
  const Rigid3 base_from_board(RotZ(0.3) * RotX(M_PI), Eigen::Vector3d(0.6, 0.1, 0.0));
  const Rigid3 flange_from_cam(RotZ(DegToRad(90.0)), Eigen::Vector3d(0.05, -0.03, 0.04));
  sim::BoardRenderOptions o;
  o.blur_sigma_px = 0.7;
  o.noise_std_grey = 2;
  o.supersampling = 6;
  Rendered out;
  for (size_t i = 0; i < spins_deg.size(); ++i) {
    const Rigid3 cam_from_board = CamFromBoard(&rng, board, DegToRad(spins_deg[i]));
    o.noise_seed = seed * 100 + i;
    out.images.push_back(renderer.Render(cam_from_board, texture, o));
    std::vector<Eigen::Vector2d> truth;
    for (int k = 0; k < board.layout.size(); ++k) {
      truth.push_back(sim::EllipseCentrePx(camera, cam_from_board * board.Centre(k),
                                           cam_from_board.rotation * Eigen::Vector3d::UnitZ(), kRadiusM));
    }
    out.truth_px.push_back(truth);
    detection::ImageRobotPose pose;
    pose.base_from_flange = base_from_board * cam_from_board.Inverse() * flange_from_cam.Inverse();
    out.poses.push_back(pose);
  }
  return out;
}

detection::DetectionOptions CirclesOptions(const Board& board, detection::Polarity polarity) {
  detection::DetectionOptions o;
  o.detector = detection::Detector::kCircles;
  o.rows = board.layout.rows;
  o.cols = board.layout.cols;
  o.asymmetric = board.layout.asymmetric;
  o.polarity = polarity;
  return o;
}

std::vector<detection::ImagePoints> DetectAndOrient(const Rendered& r, const detection::DetectionOptions& options) {
  std::vector<const vpImage<unsigned char>*> images;
  for (const vpImage<unsigned char>& i : r.images) images.push_back(&i);
  std::vector<detection::ImagePoints> points = detection::DetectAllImagePoints(images, options);
  detection::ObservationSetup setup;
  setup.camera = Pinhole();
  detection::OrientCircleGrids(options, r.poses, setup, &points);
  return points;
}

struct Score {
  int images_found = 0;
  bool one_naming = true;                // the same detected id -> true disc map in every image
  Eigen::Vector2d mean_error = Eigen::Vector2d::Zero();
  double rms_error_px = 0;
  int points = 0;
};

Score ScoreAgainstTruth(const Rendered& r, const std::vector<detection::ImagePoints>& points) {
  Score s;
  std::map<int, int> naming;  // detected id -> true disc
  double sum2 = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].ok) continue;
    ++s.images_found;
    for (const auto& [id, px] : points[i].points_px) {
      int nearest = -1;
      double best = 1e9;
      for (size_t k = 0; k < r.truth_px[i].size(); ++k) {
        const double d = (r.truth_px[i][k] - px).norm();
        if (d < best) best = d, nearest = static_cast<int>(k);
      }
      if (best > 2.0) s.one_naming = false;
      const auto [it, inserted] = naming.emplace(id, nearest);
      if (!inserted && it->second != nearest) s.one_naming = false;
      const Eigen::Vector2d e = px - r.truth_px[i][static_cast<size_t>(nearest)];
      s.mean_error += e;
      sum2 += e.squaredNorm();
      ++s.points;
    }
  }
  if (s.points > 0) {
    s.mean_error /= s.points;
    s.rms_error_px = std::sqrt(sum2 / (2.0 * s.points));
  }
  return s;
}

// The board: white dots on black, an asymmetric grid of 11 rows of 7, named the same in every image
// and centred without bias within the noise (2 grey levels, 0.7 px blur: the centroid's noise is ~0.01 px).
TEST(CircleGrid, WhiteDotAsymmetricGridIsNamedConsistentlyAndCentredWithoutBias) {
  const Board board{{11, 7, true}};
  const Rendered r = Render(board, {0, 20, -25, 170, 200, 90}, 230, 25, nullptr, 1);
  const std::vector<detection::ImagePoints> points = DetectAndOrient(r, CirclesOptions(board, detection::Polarity::kLight));
  const Score s = ScoreAgainstTruth(r, points);
  for (const detection::ImagePoints& p : points) EXPECT_TRUE(p.ok) << p.message;
  EXPECT_EQ(s.images_found, 6);
  EXPECT_EQ(s.points, 6 * 77);
  EXPECT_TRUE(s.one_naming);
  std::printf("white dots: %d points, mean error (%+.4f, %+.4f) px, RMS %.4f px per axis\n", s.points, s.mean_error.x(),
              s.mean_error.y(), s.rms_error_px);
  EXPECT_LT(s.mean_error.norm(), 0.01) << s.mean_error.transpose();
  EXPECT_LT(s.rms_error_px, 0.03);
}

// Auto polarity finds the same white-dot board, and dark dots on white as before.
TEST(CircleGrid, AutoPolarityFindsLightAndDarkDots) {
  const Board board{{11, 7, true}};
  const Rendered light = Render(board, {0, 30}, 230, 25, nullptr, 2);
  const Rendered dark = Render(board, {0, 30}, 25, 230, nullptr, 3);
  const std::vector<detection::ImagePoints> pl = DetectAndOrient(light, CirclesOptions(board, detection::Polarity::kAuto));
  const std::vector<detection::ImagePoints> pd = DetectAndOrient(dark, CirclesOptions(board, detection::Polarity::kAuto));
  for (const detection::ImagePoints& p : pl) {
    EXPECT_TRUE(p.ok) << p.message;
    EXPECT_EQ(p.polarity, detection::Polarity::kLight);
  }
  for (const detection::ImagePoints& p : pd) {
    EXPECT_TRUE(p.ok) << p.message;
    EXPECT_EQ(p.polarity, detection::Polarity::kDark);
  }
  EXPECT_TRUE(ScoreAgainstTruth(light, pl).one_naming);
  EXPECT_TRUE(ScoreAgainstTruth(dark, pd).one_naming);
}

// A symmetric 7 x 10 grid looks the same turned by 180 deg: the cameras spin all the way round, so the
// top-left rule alone names the grid two ways; the robot poses choose the one naming.
TEST(CircleGrid, SymmetricGridTurnedAllTheWayRoundIsNamedFromTheRobotPoses) {
  const Board board{{7, 10, false}};
  const Rendered r = Render(board, {0, 60, 120, 180, 240, 300, 150}, 230, 25, nullptr, 4);
  const std::vector<detection::ImagePoints> points = DetectAndOrient(r, CirclesOptions(board, detection::Polarity::kLight));
  for (const detection::ImagePoints& p : points) EXPECT_TRUE(p.ok) << p.message;
  const Score s = ScoreAgainstTruth(r, points);
  EXPECT_EQ(s.images_found, 7);
  EXPECT_TRUE(s.one_naming);
}

// A square symmetric grid (four rotations) likewise.
TEST(CircleGrid, SquareGridIsNamedFromTheRobotPoses) {
  const Board board{{6, 6, false}};
  const Rendered r = Render(board, {0, 95, 185, 270, 40}, 20, 235, nullptr, 5);
  const std::vector<detection::ImagePoints> points = DetectAndOrient(r, CirclesOptions(board, detection::Polarity::kDark));
  for (const detection::ImagePoints& p : points) EXPECT_TRUE(p.ok) << p.message;
  EXPECT_TRUE(ScoreAgainstTruth(r, points).one_naming);
}

// Two frontal views 90 deg apart of a 180-deg-symmetric grid: both namings of the second agree with the
// flange motion alike, so that image is refused with the reason, not named at random.
TEST(CircleGrid, AnOrientationThePosesCannotTellIsRefused) {
  const Board board{{7, 10, false}};
  Rendered r = Render(board, {0, 90}, 230, 25, nullptr, 6);
  // Make both views frontal: the flange poses then differ by exactly the 90 deg spin.
  const CameraIntrinsics camera = Pinhole();
  const sim::BoardRenderer renderer(camera);
  const sim::BoardTexture texture = sim::CircleGridTexture(7, 10, false, kSpacingM, kRadiusM, 230, 25, 0.012);
  const Eigen::Vector2d m = board.Middle();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d rot = RotZ(DegToRad(90.0 * i));
    const Rigid3 cam_from_board(rot, Eigen::Vector3d(0, 0, 0.35) - rot * Eigen::Vector3d(m.x(), m.y(), 0));
    r.images[static_cast<size_t>(i)] = renderer.Render(cam_from_board, texture, sim::BoardRenderOptions());
    r.poses[static_cast<size_t>(i)].base_from_flange = cam_from_board.Inverse();
  }
  const std::vector<detection::ImagePoints> points = DetectAndOrient(r, CirclesOptions(board, detection::Polarity::kLight));
  EXPECT_TRUE(points[0].ok) << points[0].message;
  EXPECT_FALSE(points[1].ok);
  EXPECT_NE(points[1].message.find("orientation cannot be told from the robot poses"), std::string::npos) << points[1].message;
}

// A textured table around the board: the circle grid is still found and named, and the raster-order
// identity keeps the dots, not the table's spots (the spots' sizes and contrasts are unlike the dots').
TEST(CircleGrid, TexturedTableAddsNoPoints) {
  const Board board{{11, 7, true}};
  const Rendered r = Render(board, {0, 25, 180}, 230, 25, Table(7), 7);
  const std::vector<detection::ImagePoints> points = DetectAndOrient(r, CirclesOptions(board, detection::Polarity::kLight));
  for (const detection::ImagePoints& p : points) EXPECT_TRUE(p.ok) << p.message;
  const Score s = ScoreAgainstTruth(r, points);
  EXPECT_EQ(s.points, 3 * 77);
  EXPECT_TRUE(s.one_naming);

  detection::DetectionOptions order;
  order.identity = detection::Identity::kOrder;
  order.polarity = detection::Polarity::kLight;
  for (size_t i = 0; i < r.images.size(); ++i) {
    const detection::ImagePoints p = detection::DetectImagePoints(r.images[i], order, nullptr);
    int on_board = 0;
    for (const auto& [id, px] : p.points_px) {
      for (const Eigen::Vector2d& t : r.truth_px[i]) on_board += (t - px).norm() < 1.0 ? 1 : 0;
    }
    EXPECT_GE(p.candidates, 100) << "the table should hold many dot-like spots: " << p.message;
    EXPECT_GE(on_board, 77) << p.message;
    EXPECT_LE(p.points_px.size(), 77u + 15u) << p.message;
  }
}

}  // namespace
}  // namespace selfcal
