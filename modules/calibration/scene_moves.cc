#include "calibration/scene_moves.h"

#include <cmath>

#include <Eigen/Geometry>

namespace selfcal::calibration {

std::vector<SceneMove> SceneMovesOf(const ObservationSet& obs, const std::map<int, Eigen::Vector3d>& dots_in_base) {
  const std::vector<std::string> names = SceneNames(obs);
  std::vector<SceneMove> moves;
  for (size_t k = 1; k < names.size(); ++k) {
    std::vector<Eigen::Vector3d> first, here;
    for (const auto& [id, p] : dots_in_base) {
      if (id < 0 || id >= kSceneDotStride) continue;
      auto other = dots_in_base.find(static_cast<int>(k) * kSceneDotStride + id);
      if (other == dots_in_base.end()) continue;
      first.push_back(p);
      here.push_back(other->second);
    }
    if (first.size() < 3) continue;
    const Eigen::Index n = static_cast<Eigen::Index>(first.size());
    Eigen::Matrix3Xd a(3, n), b(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      a.col(i) = first[i];
      b.col(i) = here[i];
    }
    SceneMove m;
    m.scene = names[k];
    m.relative_to = names[0];
    m.shared_points = static_cast<int>(n);
    const Eigen::VectorXd displacement = (b - a).colwise().norm();
    m.displacement_rms_m = std::sqrt(displacement.squaredNorm() / n);
    m.displacement_max_m = displacement.maxCoeff();
    const Eigen::Matrix4d t = Eigen::umeyama(a, b, false);
    m.rotation_rad = Eigen::AngleAxisd(Eigen::Matrix3d(t.topLeftCorner<3, 3>())).angle();
    const Eigen::Matrix3Xd fitted = (t.topLeftCorner<3, 3>() * a).colwise() + t.topRightCorner<3, 1>();
    m.rigid_fit_rms_m = std::sqrt((b - fitted).colwise().squaredNorm().sum() / n);
    m.moved = m.displacement_rms_m > kSceneMovedFactor * m.rigid_fit_rms_m && m.displacement_rms_m > kSceneMovedMinM;
    moves.push_back(m);
  }
  return moves;
}

}  // namespace selfcal::calibration
