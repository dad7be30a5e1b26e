#include "calibration/scene_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <Eigen/Geometry>

#include "calibration/scene_moves.h"
#include "calibration/scene_shift.h"

namespace selfcal::calibration {
namespace {

// One image's dots with a solved point (its camera the model's) and the move of the points that best explains
// them alone.
struct ImageDots {
  int pose = -1;  // into obs.poses
  std::vector<ShiftDot> dots;
  SceneShift own;
};

// A dot that does not project under another image's move counts this much per coordinate.
constexpr double kLostPx = 100;

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The two medoids (indices) that minimise the sum of every image's distance to the nearer one.
std::pair<int, int> TwoMedoids(const Eigen::MatrixXd& d) {
  const Eigen::Index n = d.rows();
  double best = std::numeric_limits<double>::infinity();
  std::pair<int, int> medoids{0, 1};
  for (Eigen::Index a = 0; a < n; ++a) {
    for (Eigen::Index b = a + 1; b < n; ++b) {
      const double cost = d.col(a).cwiseMin(d.col(b)).sum();
      if (cost < best) {
        best = cost;
        medoids = {static_cast<int>(a), static_cast<int>(b)};
      }
    }
  }
  return medoids;
}

// Every image with at least 4 dots among `points` whose own move could be fitted.
std::vector<ImageDots> ImagesWithMoves(const ObservationSet& obs, const RobotModel& robot, const Eigen::VectorXd& rho,
                                       const CameraIntrinsics& camera, const std::map<int, Eigen::Vector3d>& points) {
  std::vector<ImageDots> images;
  for (std::size_t i = 0; i < obs.poses.size(); ++i) {
    ImageDots image;
    image.pose = static_cast<int>(i);
    image.dots = ShiftDotsOf(obs, {image.pose}, robot, rho, points);
    if (image.dots.size() < 4) continue;
    image.own = SceneShiftOfDots(image.dots, camera);
    if (!image.own.computed || !std::isfinite(image.own.rms_after_px)) continue;
    images.push_back(std::move(image));
  }
  return images;
}

}  // namespace

SceneSplit FindSceneSplit(const ObservationSet& obs, const RobotModel& robot, const Eigen::VectorXd& rho,
                          const CameraIntrinsics& camera, const std::map<int, Eigen::Vector3d>& points) {
  SceneSplit split;
  // A solve that stopped on non-finite values (an unconverged bundle) gives nothing to compare.
  if (!rho.allFinite()) return split;
  for (const auto& [id, p] : points) {
    if (!p.allFinite()) return split;
  }
  const std::vector<ImageDots> images = ImagesWithMoves(obs, robot, rho, camera, points);
  const int n = static_cast<int>(images.size());
  split.images = n;
  if (n < 2 * kSplitMinPoses) return split;
  // d(a, b): the RMS (px) that each image gains with the other's move instead of its own, averaged over the two.
  Eigen::MatrixXd own(n, 1), d = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < n; ++a) own(a) = MeanSquareAfter(images[a].dots, camera, images[a].own, kLostPx);
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double gain = MeanSquareAfter(images[a].dots, camera, images[b].own, kLostPx) - own(a) +
                          MeanSquareAfter(images[b].dots, camera, images[a].own, kLostPx) - own(b);
      d(a, b) = d(b, a) = std::sqrt(std::max(0.0, gain / 2));
    }
  }
  const auto [ma, mb] = TwoMedoids(d);
  std::vector<int> group(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) group[static_cast<std::size_t>(i)] = d(i, ma) <= d(i, mb) ? 0 : 1;
  const int first = group[0];  // the first group is the one of the first image
  std::vector<double> scatter[2];
  std::vector<int> poses[2];
  int identification[2] = {0, 0};
  for (int i = 0; i < n; ++i) {
    const int g = group[static_cast<std::size_t>(i)] == first ? 0 : 1;
    poses[g].push_back(images[static_cast<std::size_t>(i)].pose);
    identification[g] += obs.poses[static_cast<std::size_t>(images[i].pose)].role == PoseRole::kIdentification ? 1 : 0;
    if (i != ma && i != mb) scatter[g].push_back(std::min(d(i, ma), d(i, mb)));  // to its own medoid
  }
  split.separation_px = d(ma, mb);
  split.scatter_first_px = Median(scatter[0]);
  split.scatter_second_px = Median(scatter[1]);
  // One move per group, the cameras held: how much of the one-place residual the two places explain.
  double before = 0, after = 0, coordinates = 0;
  SceneShift group_move[2];
  for (int g = 0; g < 2; ++g) {
    if (poses[g].empty()) continue;  // every image nearer one medoid (a scene seen without error)
    group_move[g] = SceneShiftOfPoses(obs, poses[g], robot, rho, camera, points);
    const SceneShift& shift = group_move[g];
    if (!shift.computed || !std::isfinite(shift.rms_after_px) || !std::isfinite(shift.rms_before_px)) return split;
    before += shift.rms_before_px * shift.rms_before_px * 2 * shift.dots;
    after += shift.rms_after_px * shift.rms_after_px * 2 * shift.dots;
    coordinates += 2 * shift.dots;
  }
  split.rms_one_place_px = std::sqrt(before / coordinates);
  split.rms_two_places_px = std::sqrt(after / coordinates);
  split.checked = true;
  // The move from the first group's place of the points to the second's.
  Eigen::Matrix3Xd a(3, static_cast<Eigen::Index>(points.size())), b(3, static_cast<Eigen::Index>(points.size()));
  Eigen::Index k = 0;
  for (const auto& [id, p] : points) {
    a.col(k) = group_move[0].Moved(p);
    b.col(k++) = group_move[1].Moved(p);
  }
  const Eigen::Matrix4d t = Eigen::umeyama(a, b, false);
  const Eigen::Matrix3d r = t.topLeftCorner<3, 3>();
  const Eigen::Vector3d centroid = a.rowwise().mean();
  split.rotation_rad = Eigen::AngleAxisd(r).angle();
  split.translation_m = (r * centroid + t.topRightCorner<3, 1>() - centroid).norm();
  split.found = std::min(identification[0], identification[1]) >= kSplitMinPoses &&
                split.rms_two_places_px * kSplitRmsRatio <= split.rms_one_place_px &&
                (split.translation_m >= kSceneMovedMinM || split.rotation_rad >= kSceneMovedMinRad);
  if (!split.found) return split;
  for (int g = 0; g < 2; ++g) {
    for (const int index : poses[g]) {
      (g == 0 ? split.first_poses : split.second_poses).push_back(obs.poses[static_cast<std::size_t>(index)].id);
    }
  }
  return split;
}

ObservationSet WithSplitScenes(const ObservationSet& obs, const SceneSplit& split) {
  const std::set<std::string> second(split.second_poses.begin(), split.second_poses.end());
  ObservationSet named = obs;
  for (PoseObservation& pose : named.poses) pose.scene = second.count(pose.id) ? "scene 2" : "scene 1";
  return SeparateScenes(named);
}

}  // namespace selfcal::calibration
