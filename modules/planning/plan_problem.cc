#include "planning/plan_problem.h"

#include <cmath>
#include <random>
#include <sstream>

namespace selfcal::planning {

Scene Scene::FromBox(const Eigen::Vector3d& center_m, const Eigen::Vector3d& size_m, int num_dots, uint64_t seed) {
  Scene scene;
  const Eigen::Vector3d half = 0.5 * size_m;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
    scene.extent_in_base.push_back(center_m + sign.cwiseProduct(half));
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < num_dots; ++k) {
    const double x = unit(rng), y = unit(rng), z = unit(rng);
    scene.dots_in_base.push_back(center_m + Eigen::Vector3d(x, y, z).cwiseProduct(half));
  }
  return scene;
}

Scene Scene::FromDots(const std::vector<Eigen::Vector3d>& dots_in_base) {
  Scene scene;
  scene.dots_in_base = dots_in_base;
  // The extent is every dot: a subset (the dots extreme along a few hundred directions) misses hull
  // vertices, and the planner then returned poses with a dot outside the image that the check refused.
  scene.extent_in_base = dots_in_base;
  return scene;
}

Eigen::Vector3d Scene::Centre() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : extent_in_base) sum += p;
  return extent_in_base.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(extent_in_base.size()));
}

std::string Scene::Validate() const {
  std::ostringstream out;
  if (dots_in_base.size() < 8) out << "the scene has " << dots_in_base.size() << " dots; at least 8 are needed\n";
  if (extent_in_base.empty()) out << "the scene has no extent points\n";
  for (size_t k = 0; k < dots_in_base.size(); ++k) {
    if (!dots_in_base[k].allFinite()) out << "scene dot " << k << " is not finite\n";
  }
  for (size_t k = 0; k < extent_in_base.size(); ++k) {
    if (!extent_in_base[k].allFinite()) out << "scene extent point " << k << " is not finite\n";
  }
  std::string s = out.str();
  if (!s.empty()) s.pop_back();
  return s;
}

std::string PlanConstraints::Validate() const {
  std::ostringstream out;
  auto positive = [&out](const char* name, double v) {
    if (!(std::isfinite(v) && v > 0)) out << name << " = " << v << " must be positive\n";
  };
  auto non_negative = [&out](const char* name, double v) {
    if (!(std::isfinite(v) && v >= 0)) out << name << " = " << v << " must be >= 0\n";
  };
  non_negative("joint_margin_rad", joint_margin_rad);
  non_negative("image_margin_px", image_margin_px);
  positive("min_depth_m", min_depth_m);
  if (!(max_depth_m > min_depth_m)) out << "max_depth_m = " << max_depth_m << " must exceed min_depth_m\n";
  non_negative("min_spread_m", min_spread_m);
  positive("max_image_motion_px", max_image_motion_px);
  positive("max_fx_stddev_rel", max_fx_stddev_rel);
  positive("pixel_noise_px", pixel_noise_px);
  if (!(min_axis_sine >= 0 && min_axis_sine < 1)) out << "min_axis_sine = " << min_axis_sine << " must lie in [0, 1)\n";
  positive("max_joint_travel_rad", max_joint_travel_rad);
  positive("max_viewing_angle_rad", max_viewing_angle_rad);
  if (min_identification_poses < 3) out << "min_identification_poses = " << min_identification_poses << " must be >= 3\n";
  if (!(max_condition_number > 1)) out << "max_condition_number = " << max_condition_number << " must exceed 1\n";
  std::string s = out.str();
  if (!s.empty()) s.pop_back();
  return s;
}

std::string PlanningProblem::Validate() const {
  std::ostringstream out;
  const std::string robot_problems = robot.Validate();
  if (!robot_problems.empty()) out << robot_problems << "\n";
  const std::string camera_problems = camera.Validate();
  if (!camera_problems.empty()) out << camera_problems << "\n";
  const std::string scene_problems = scene.Validate();
  if (!scene_problems.empty()) out << scene_problems << "\n";
  const std::string constraint_problems = constraints.Validate();
  if (!constraint_problems.empty()) out << constraint_problems << "\n";
  if (num_identification_poses < 3) out << "num_identification_poses = " << num_identification_poses << " must be >= 3\n";
  std::string s = out.str();
  if (!s.empty()) s.pop_back();
  return s;
}

}  // namespace selfcal::planning
