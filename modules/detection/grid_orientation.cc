#include "detection/grid_orientation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "detection/circle_grid.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::detection {

namespace {

// cam_from_layout's rotation for the points of one image named through `perm` (id k takes the pixel of
// id perm[k]).
Eigen::Matrix3d CamFromLayout(const CircleGridLayout& layout, const std::map<int, Eigen::Vector2d>& px,
                              const std::vector<int>& perm, const CameraIntrinsics& camera) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int k = 0; k < layout.size(); ++k) {
    const Eigen::Vector2d l = layout.Point(k), p = px.at(perm[static_cast<size_t>(k)]);
    object.emplace_back(l.x(), l.y(), 0);
    image.emplace_back(p.x(), p.y());
  }
  const cv::Matx33d k(camera.fx_px, 0, camera.cx_px, 0, camera.fy_px(), camera.cy_px, 0, 0, 1);
  const std::vector<double> dist = {camera.k1, camera.k2, camera.p1, camera.p2, camera.k3};
  cv::Vec3d rvec, tvec;
  cv::solvePnP(object, image, k, dist, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d out;
  cv::cv2eigen(r, out);
  return out;
}

Eigen::Matrix3d FlangeRotation(const ImageRobotPose& pose, const RobotModel& robot) {
  if (pose.base_from_flange) return pose.base_from_flange->rotation;
  return BaseFromFlange(robot, Eigen::VectorXd::Zero(robot.num_parameters()), pose.joints_rad).rotation;
}

struct Candidates {
  std::vector<Eigen::Matrix3d> cam_from_layout;  // per rotation
  Eigen::Matrix3d base_from_flange;
  int chosen = -1;
};

// Median |angle(camera motion) - angle(flange motion)| of image j under rotation s against the oriented.
double Disagreement(const std::vector<Candidates>& c, size_t j, size_t s) {
  std::vector<double> d;
  for (const Candidates& k : c) {
    if (k.chosen < 0) continue;
    const double cam = RotationAngle(k.cam_from_layout[static_cast<size_t>(k.chosen)] * c[j].cam_from_layout[s].transpose());
    const double flange = RotationAngle(k.base_from_flange.transpose() * c[j].base_from_flange);
    d.push_back(std::abs(cam - flange));
  }
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace

void OrientCircleGrids(const DetectionOptions& options, const std::vector<ImageRobotPose>& robot_poses,
                       const ObservationSetup& setup, std::vector<ImagePoints>* points,
                       const GridOrientationOptions& orientation) {
  SELFCAL_CHECK(points->size() == robot_poses.size(), "OrientCircleGrids: one robot pose per image");
  if (options.detector != Detector::kCircles) return;
  const CircleGridLayout layout{options.rows, options.cols, options.asymmetric};
  std::vector<LayoutSymmetry> rotations;
  for (const LayoutSymmetry& s : LayoutSymmetries(layout)) {
    if (s.rotation) rotations.push_back(s);
  }
  if (rotations.size() < 2) return;
  std::vector<Candidates> c(points->size());
  bool first = true;
  for (size_t i = 0; i < points->size(); ++i) {
    if (!(*points)[i].ok) continue;
    for (const LayoutSymmetry& s : rotations) c[i].cam_from_layout.push_back(CamFromLayout(layout, (*points)[i].points_px, s.perm, setup.camera));
    c[i].base_from_flange = FlangeRotation(robot_poses[i], setup.robot);
    if (first) c[i].chosen = 0, first = false;
  }
  for (;;) {
    size_t best_image = c.size(), best_rotation = 0;
    double best_margin = -1;
    for (size_t j = 0; j < c.size(); ++j) {
      if (c[j].cam_from_layout.empty() || c[j].chosen >= 0) continue;
      std::vector<std::pair<double, size_t>> d;
      for (size_t s = 0; s < rotations.size(); ++s) d.emplace_back(Disagreement(c, j, s), s);
      std::sort(d.begin(), d.end());
      if (d[1].first - d[0].first > best_margin) best_margin = d[1].first - d[0].first, best_image = j, best_rotation = d[0].second;
    }
    if (best_image == c.size() || best_margin < DegToRad(orientation.min_margin_deg)) break;
    c[best_image].chosen = static_cast<int>(best_rotation);
    ImagePoints& p = (*points)[best_image];
    const double off_deg = RadToDeg(Disagreement(c, best_image, best_rotation));
    if (best_rotation != 0) {
      std::map<int, Eigen::Vector2d> turned;
      for (int k = 0; k < layout.size(); ++k) turned[k] = p.points_px.at(rotations[best_rotation].perm[static_cast<size_t>(k)]);
      p.points_px = std::move(turned);
    }
    std::ostringstream m;
    m.precision(2);
    m << std::fixed << "; turned by " << RadToDeg(rotations[best_rotation].angle_rad) << " deg to agree with the robot poses (camera and flange rotations "
      << off_deg << " deg apart)";
    p.message += m.str();
  }
  for (size_t j = 0; j < c.size(); ++j) {
    if (c[j].cam_from_layout.empty() || c[j].chosen >= 0) continue;
    std::vector<double> d;
    for (size_t s = 0; s < rotations.size(); ++s) d.push_back(RadToDeg(Disagreement(c, j, s)));
    std::ostringstream m;
    m.precision(1);
    m << std::fixed << "the grid's orientation cannot be told from the robot poses: its rotations disagree with the flange motions by";
    for (size_t s = 0; s < d.size(); ++s) m << (s ? ", " : " ") << d[s] << " deg (turned " << RadToDeg(rotations[s].angle_rad) << ")";
    m << "; none by " << orientation.min_margin_deg << " deg less than the others (" << (*points)[j].message << ")";
    (*points)[j].ok = false;
    (*points)[j].message = m.str();
  }
}

}  // namespace selfcal::detection
