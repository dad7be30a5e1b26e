#include "observations/observation_set.h"

#include <algorithm>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace selfcal {

const char* PoseRoleName(PoseRole role) {
  return role == PoseRole::kIdentification ? "identification" : "verification";
}

std::vector<int> ObservationSet::PosesWithRole(PoseRole role) const {
  std::vector<int> out;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].role == role) out.push_back(static_cast<int>(i));
  }
  return out;
}

RobotModel FlangePoseModel(const Rigid3& flange_from_cam) {
  RobotModel model;
  model.name = "flange poses";
  model.flange_from_cam = flange_from_cam;
  return model;
}

bool ObservationSet::UsesFlangePoses() const {
  if (poses.empty() || robot.num_joints() != 0) return false;
  for (const PoseObservation& pose : poses) {
    if (!pose.base_from_flange) return false;
  }
  return true;
}

Rigid3 BaseFromCamAt(const RobotModel& robot, const Eigen::VectorXd& rho, const PoseObservation& pose) {
  if (pose.base_from_flange) return BaseFromCamGivenFlange<double>(robot, rho.data(), *pose.base_from_flange);
  return BaseFromCam(robot, rho, pose.joints_rad);
}

Rigid3 PointsFromCamAt(const RobotModel& robot, const Eigen::VectorXd& rho, const PoseObservation& pose) {
  if (pose.base_from_flange) return PointsFromCamGivenFlange<double>(robot, rho.data(), *pose.base_from_flange);
  return PointsFromCam(robot, rho, pose.joints_rad);
}

namespace {

// A scene that only verification poses see: none of its points can be placed, so those poses verify
// nothing. Named at its first pose. Nothing when the set has no identification pose at all.
std::string ScenesWithoutIdentification(const std::vector<PoseObservation>& poses) {
  std::map<std::string, std::string> first_pose;  // scene -> its first pose id
  std::set<std::string> identified;
  for (const PoseObservation& pose : poses) {
    first_pose.emplace(pose.scene, pose.id);
    if (pose.role == PoseRole::kIdentification) identified.insert(pose.scene);
  }
  std::ostringstream out;
  if (identified.empty() || first_pose.size() < 2) return out.str();
  for (const auto& [scene, id] : first_pose) {
    if (identified.count(scene)) continue;
    out << "pose " << id << ": "
        << (scene.empty() ? std::string("the poses without a `scene` key see a scene")
                          : "its scene `" + scene + "` is a scene")
        << " that no identification pose sees, so none of its points can be placed (give it identification "
           "poses, or name a scene that has them)\n";
  }
  return out.str();
}

}  // namespace

std::string ObservationSet::Validate() const {
  std::ostringstream out;
  bool any_flange_pose = false;
  for (const PoseObservation& pose : poses) any_flange_pose |= pose.base_from_flange.has_value();
  // A flange-pose set's model has no joints: only its hand-eye transform is the robot's part.
  if (robot.num_joints() != 0 || !any_flange_pose) out << robot.Validate();
  out << camera.Validate();
  if (!(pixel_noise_px >= kMinPixelNoisePx && pixel_noise_px <= kMaxPixelNoisePx)) {
    out << "pixel_noise_px = " << pixel_noise_px << " must lie in [" << kMinPixelNoisePx << ", " << kMaxPixelNoisePx
        << "] px\n";
  }
  std::set<std::string> ids;
  std::set<int> seen_dots;
  for (const PoseObservation& pose : poses) {
    if (!ids.insert(pose.id).second) out << "pose " << pose.id << ": duplicate pose id\n";
    if (pose.base_from_flange) {
      if (robot.num_joints() != 0) {
        out << "pose " << pose.id << ": gives a flange pose, but the robot has joints (give joint angles with a "
            << "robot, or flange poses without one)\n";
      }
      if (!pose.base_from_flange->translation.allFinite() || !pose.base_from_flange->rotation.allFinite()) {
        out << "pose " << pose.id << ": the flange pose is not finite\n";
      }
    } else if (robot.num_joints() == 0) {
      out << "pose " << pose.id << ": no flange pose (a set without a robot needs base_from_flange in every pose)\n";
    }
    if (pose.joints_rad.size() != robot.num_joints()) {
      out << "pose " << pose.id << ": " << pose.joints_rad.size() << " joint values, the robot has "
          << robot.num_joints() << "\n";
    }
    for (int j = 0; j < pose.joints_rad.size(); ++j) {
      if (!std::isfinite(pose.joints_rad[j])) out << "pose " << pose.id << ": joint " << j + 1 << " is not finite\n";
    }
    for (const auto& [dot, px] : pose.dots_px) {
      if (!px.allFinite()) out << "pose " << pose.id << ", dot " << dot << ": non-finite pixel\n";
      seen_dots.insert(dot);
    }
  }
  out << ScenesWithoutIdentification(poses);
  auto check_distance = [&](const KnownDistance& k, const char* what) {
    if (!std::isfinite(k.length_m) || k.length_m <= 0) {
      out << what << " " << k.dot_a << "-" << k.dot_b << ": length " << k.length_m << " m must be finite and > 0\n";
    }
    if (k.dot_a == k.dot_b) out << what << " " << k.dot_a << "-" << k.dot_b << ": both ends are the same dot\n";
    for (int dot : {k.dot_a, k.dot_b}) {
      if (!seen_dots.count(dot)) out << what << " " << k.dot_a << "-" << k.dot_b << ": dot " << dot << " is never observed\n";
    }
  };
  for (const KnownDistance& k : yardsticks) check_distance(k, "yardstick");
  for (const KnownDistance& k : check_distances) check_distance(k, "check distance");
  return out.str();
}

Matches MatchById(const PoseObservation& a, const PoseObservation& b) {
  Matches m;
  for (const auto& [dot, px] : a.dots_px) {
    auto it = b.dots_px.find(dot);
    if (it == b.dots_px.end()) continue;
    m.dot_ids.push_back(dot);
    m.pixels_a.push_back(px);
    m.pixels_b.push_back(it->second);
  }
  return m;
}

std::vector<std::string> SceneNames(const ObservationSet& observations) {
  std::vector<std::string> names;
  for (const PoseObservation& pose : observations.poses) {
    if (std::find(names.begin(), names.end(), pose.scene) == names.end()) names.push_back(pose.scene);
  }
  return names;
}

ObservationSet SeparateScenes(const ObservationSet& observations, std::vector<std::string>* scenes) {
  const std::vector<std::string> names = SceneNames(observations);
  if (scenes != nullptr) *scenes = names;
  if (names.size() <= 1) return observations;
  ObservationSet out = observations;
  for (PoseObservation& pose : out.poses) {
    const int k = static_cast<int>(std::find(names.begin(), names.end(), pose.scene) - names.begin());
    std::map<int, Eigen::Vector2d> moved;
    for (const auto& [dot, pixel] : pose.dots_px) moved[k * kSceneDotStride + dot] = pixel;
    pose.dots_px = std::move(moved);
  }
  const auto repeat = [&](const std::vector<KnownDistance>& list) {
    std::vector<KnownDistance> all;
    for (size_t k = 0; k < names.size(); ++k) {
      for (KnownDistance d : list) {
        d.dot_a += static_cast<int>(k) * kSceneDotStride;
        d.dot_b += static_cast<int>(k) * kSceneDotStride;
        all.push_back(d);
      }
    }
    return all;
  };
  out.yardsticks = repeat(observations.yardsticks);
  out.check_distances = repeat(observations.check_distances);
  return out;
}

}  // namespace selfcal
