// selfcal_corner_precision: how well ChArUco corners fit the true board, selfcal's detector beside OpenCV's.
//
// Per image, the board's inner corners by five methods:
//   selfcal charuco       detection::DetectCharuco (detection/charuco.h);
//   opencv interpolate    cv::aruco::detectMarkers + cv::aruco::interpolateCornersCharuco (no camera matrix);
//   cornerSubPix 7x7      cv::cornerSubPix(winSize 3 x 3: a 7 x 7 px window) from OpenCV's interpolated corners;
//   cornerSubPix 15x15    cv::cornerSubPix(winSize 7 x 7) from the same;
//   selfcal chessboard    detection::DetectChessboard on the (rows - 1) x (cols - 1) inner corners, named by the
//                         nearest ChArUco corner of selfcal's within 3 px.
// Scored on the ids every method found in the image: the RMS distance (px) of the corners to the board's
// known corners (square and marker length) projected with the best camera pose (cv::solvePnP, iterative,
// with the camera file's intrinsics and distortion), and on rendered boards also the RMS distance to the true
// corners and the mean error (bias).
//
//   selfcal_corner_precision --camera-file F --dictionary D --board 5x7 --square-mm 34 --marker-mm 28 IMAGE...
//   selfcal_corner_precision ... --render 20 [--noise-grey 2] [--blur-px 0.7] [--seed 1]
// --render N renders N boards (sim/board_renderer.h: anti-aliased, the camera file's lens, random poses
// 0.3-0.6 m away, tilted up to 45 deg) instead of reading images.
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detection/charuco.h"
#include "detection/charuco_pattern.h"
#include "detection/chessboard.h"
#include "geometry/rigid3.h"
#include "io/camera_file.h"
#include "sim/board_renderer.h"

namespace {

using namespace selfcal;
using Corners = std::map<int, Eigen::Vector2d>;

const char* const kMethods[] = {"selfcal charuco", "opencv interpolate", "cornerSubPix 7x7", "cornerSubPix 15x15",
                                "selfcal chessboard"};
constexpr int kNumMethods = 5;

struct Score {
  double sum_pnp2 = 0, sum_truth2 = 0;
  Eigen::Vector2d sum_error = Eigen::Vector2d::Zero();
  int n = 0, images = 0;
};

Corners ToCorners(const std::vector<cv::Point2f>& c, const std::vector<int>& ids) {
  Corners out;
  for (size_t k = 0; k < c.size(); ++k) out[ids[k]] = Eigen::Vector2d(c[k].x, c[k].y);
  return out;
}

// The five methods' corners of one image (a method that finds nothing gives an empty map).
std::vector<Corners> AllMethods(const vpImage<unsigned char>& image, const detection::CharucoOptions& options,
                                const cv::Ptr<cv::aruco::CharucoBoard>& board) {
  std::vector<Corners> out(kNumMethods);
  out[0] = detection::DetectCharuco(image, options).corners_px;
  const cv::Mat mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1, image.bitmap);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(mat, board->dictionary, marker_corners, marker_ids);
  std::vector<cv::Point2f> cc;
  std::vector<int> cids;
  if (!marker_ids.empty()) cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, mat, board, cc, cids);
  out[1] = ToCorners(cc, cids);
  const cv::TermCriteria term(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4);
  for (int m = 2; m <= 3; ++m) {
    std::vector<cv::Point2f> refined = cc;
    if (!refined.empty()) cv::cornerSubPix(mat, refined, m == 2 ? cv::Size(3, 3) : cv::Size(7, 7), cv::Size(-1, -1), term);
    out[static_cast<size_t>(m)] = ToCorners(refined, cids);
  }
  detection::ChessboardOptions co;
  co.rows = options.rows - 1;
  co.cols = options.cols - 1;
  const detection::ChessboardDetection chess = detection::DetectChessboard(image, co, {});
  for (const Eigen::Vector2d& p : chess.corners_px) {
    for (const auto& [id, q] : out[0]) {
      if ((p - q).norm() < 3) out[4][id] = p;
    }
  }
  return out;
}

// RMS residual px of the best pose of `ids` of `c` (squared sum added to *sum2), with the board's corners.
void ScorePnp(const Corners& c, const std::vector<int>& ids, const std::vector<Eigen::Vector3d>& board_m,
              const cv::Mat& k, const cv::Mat& dist, double* sum2, std::pair<double, int>* worst_out = nullptr) {
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  for (int id : ids) {
    const Eigen::Vector3d& x = board_m[static_cast<size_t>(id)];
    obj.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()), 0.f);
    img.emplace_back(static_cast<float>(c.at(id).x()), static_cast<float>(c.at(id).y()));
  }
  cv::Mat rvec, tvec;
  cv::solvePnP(obj, img, k, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE);
  std::vector<cv::Point2f> projected;
  cv::projectPoints(obj, rvec, tvec, k, dist, projected);
  double worst = 0;
  int worst_id = -1;
  for (size_t i = 0; i < img.size(); ++i) {
    const double e = cv::norm(projected[i] - img[i]);
    *sum2 += e * e;
    if (e > worst) {
      worst = e;
      worst_id = ids[i];
    }
  }
  if (worst_out != nullptr) *worst_out = {worst, worst_id};
}

// A random board pose: the board's centre 0.3-0.6 m in front, near the optical axis, tilted up to 45 deg,
// turned about its normal at random.
Rigid3 RandomPose(std::mt19937_64* rng, const Eigen::Vector2d& board_centre_m) {
  std::uniform_real_distribution<double> unit(0, 1);
  const double depth = 0.3 + 0.3 * unit(*rng), tilt = DegToRad(45) * unit(*rng), tilt_dir = 2 * M_PI * unit(*rng);
  const double spin = 2 * M_PI * unit(*rng);
  // At no tilt the board's x and y along the image's u and v (the printed face seen from the board's -z side).
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(tilt_dir), std::sin(tilt_dir), 0)).toRotationMatrix() *
                            Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d centre_in_cam(0.03 * (2 * unit(*rng) - 1), 0.02 * (2 * unit(*rng) - 1), depth);
  return Rigid3(r, centre_in_cam - r * Eigen::Vector3d(board_centre_m.x(), board_centre_m.y(), 0));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("ChArUco corner precision: selfcal's detector beside OpenCV's, against the true board");
  std::string camera_file, dictionary = "DICT_6X6_250", board_text = "5x7";
  double square_mm = 34, marker_mm = 28, noise_grey = 2, blur_px = 0.7;
  int render = 0;
  uint64_t seed = 1;
  std::vector<std::string> images;
  app.add_option("--camera-file", camera_file, "OpenCV camera file (intrinsics and distortion)")->required();
  app.add_option("--dictionary", dictionary);
  app.add_option("--board", board_text, "squares XxY (OpenCV's squaresX x squaresY)");
  app.add_option("--square-mm", square_mm);
  app.add_option("--marker-mm", marker_mm);
  app.add_option("--render", render, "render N boards instead of reading images");
  app.add_option("--noise-grey", noise_grey, "rendered: pixel noise, grey levels");
  app.add_option("--blur-px", blur_px, "rendered: Gaussian blur sigma, px");
  app.add_option("--seed", seed);
  std::string write_rendered;
  bool verbose = false;
  app.add_flag("--verbose", verbose, "each image's largest residual per method");
  app.add_option("--write-rendered", write_rendered, "rendered: also write each image as DIR/board_N.png");
  app.add_option("images", images);
  CLI11_PARSE(app, argc, argv);

  detection::CharucoOptions options;
  options.dictionary = dictionary;
  if (std::sscanf(board_text.c_str(), "%dx%d", &options.cols, &options.rows) != 2) return 2;
  if (Status s = options.Validate(); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 2;
  }
  const Result<CameraIntrinsics> camera = io::LoadCameraFile(camera_file, "");
  if (!camera.ok()) {
    std::fprintf(stderr, "%s\n", camera.status().message().c_str());
    return 2;
  }
  const cv::Mat k = (cv::Mat_<double>(3, 3) << camera->fx_px, 0, camera->cx_px, 0, camera->fy_px(), camera->cy_px, 0, 0, 1);
  const cv::Mat dist = (cv::Mat_<double>(1, 5) << camera->k1, camera->k2, camera->p1, camera->p2, camera->k3);
  const detection::CharucoPattern pattern(options, square_mm * 1e-3, marker_mm * 1e-3);
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      options.cols, options.rows, static_cast<float>(square_mm * 1e-3), static_cast<float>(marker_mm * 1e-3),
      cv::aruco::getPredefinedDictionary(static_cast<int>(
          std::find(detection::CharucoDictionaryNames().begin(), detection::CharucoDictionaryNames().end(), dictionary) -
          detection::CharucoDictionaryNames().begin())));
  std::mt19937_64 rng(seed);
  const sim::BoardRenderer renderer(*camera);
  std::vector<Score> scores(kNumMethods);
  const int count = render > 0 ? render : static_cast<int>(images.size());
  int scored = 0;
  for (int i = 0; i < count; ++i) {
    vpImage<unsigned char> image;
    Corners truth;
    if (render > 0) {
      const Rigid3 cam_from_board = RandomPose(&rng, 0.5e-3 * Eigen::Vector2d(options.cols * square_mm, options.rows * square_mm));
      sim::BoardRenderOptions ro;
      ro.off_plane_grey = 90;
      ro.blur_sigma_px = blur_px;
      ro.noise_std_grey = noise_grey;
      ro.noise_seed = seed * 1000 + static_cast<uint64_t>(i);
      image = renderer.Render(cam_from_board, [&](double x, double y) { return pattern.DarkAt(x, y) ? 40.0 : 210.0; }, ro);
      if (!write_rendered.empty()) {
        cv::Mat out(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1, image.bitmap);
        cv::imwrite(write_rendered + "/board_" + std::to_string(i) + ".png", out);
      }
      for (size_t id = 0; id < pattern.corners_m().size(); ++id) {
        if (const auto p = Project(*camera, cam_from_board * pattern.corners_m()[id])) truth[static_cast<int>(id)] = *p;
      }
    } else {
      const cv::Mat grey = cv::imread(images[static_cast<size_t>(i)], cv::IMREAD_GRAYSCALE);
      if (grey.empty()) {
        std::fprintf(stderr, "cannot read %s\n", images[static_cast<size_t>(i)].c_str());
        return 2;
      }
      image.resize(static_cast<unsigned>(grey.rows), static_cast<unsigned>(grey.cols));
      for (int v = 0; v < grey.rows; ++v) std::copy(grey.ptr(v), grey.ptr(v) + grey.cols, image[static_cast<unsigned>(v)]);
    }
    const std::vector<Corners> found = AllMethods(image, options, board);
    std::vector<int> ids;
    for (const auto& [id, p] : found[0]) {
      bool everywhere = true;
      for (const Corners& c : found) everywhere = everywhere && c.count(id) > 0;
      if (everywhere) ids.push_back(id);
    }
    std::printf("image %d: %zu %zu %zu %zu %zu corners, %zu common\n", i, found[0].size(), found[1].size(), found[2].size(),
                found[3].size(), found[4].size(), ids.size());
    if (ids.size() < 6) continue;
    ++scored;
    for (int m = 0; m < kNumMethods; ++m) {
      Score& s = scores[static_cast<size_t>(m)];
      std::pair<double, int> worst;
      ScorePnp(found[static_cast<size_t>(m)], ids, pattern.corners_m(), k, dist, &s.sum_pnp2, &worst);
      if (verbose) std::printf("  %-20s largest PnP residual %.3f px (corner %d)\n", kMethods[m], worst.first, worst.second);
      for (int id : ids) {
        if (render > 0) {
          const Eigen::Vector2d e = found[static_cast<size_t>(m)].at(id) - truth.at(id);
          s.sum_truth2 += e.squaredNorm();
          s.sum_error += e;
        }
      }
      s.n += static_cast<int>(ids.size());
      ++s.images;
    }
  }
  std::printf("\n%d of %d images scored (every method found >= 6 common corners)\n", scored, count);
  std::printf("%-20s %8s %12s", "method", "corners", "PnP RMS px");
  if (render > 0) std::printf(" %14s %18s", "truth RMS px", "mean error px");
  std::printf("\n");
  for (int m = 0; m < kNumMethods; ++m) {
    const Score& s = scores[static_cast<size_t>(m)];
    if (s.n == 0) continue;
    std::printf("%-20s %8d %12.4f", kMethods[m], s.n, std::sqrt(s.sum_pnp2 / s.n));
    if (render > 0) {
      std::printf(" %14.4f   (%+.4f, %+.4f)", std::sqrt(s.sum_truth2 / s.n), s.sum_error.x() / s.n, s.sum_error.y() / s.n);
    }
    std::printf("\n");
  }
  return 0;
}
