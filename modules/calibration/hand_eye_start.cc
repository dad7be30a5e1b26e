#include "calibration/hand_eye_start.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/Dense>

namespace selfcal::calibration {

namespace {

double RotationAngle(const Eigen::Matrix3d& r) { return LogSO3(r).norm(); }

// Pairs (i, j) of identification poses, i < j, nearest in file order first (the most shared dots).
std::vector<std::pair<int, int>> PairOrder(const std::vector<int>& poses, int max_pairs) {
  std::vector<std::pair<int, int>> pairs;
  const int n = static_cast<int>(poses.size());
  for (int gap = 1; gap < n; ++gap) {
    for (int i = 0; i + gap < n; ++i) {
      if (static_cast<int>(pairs.size()) >= max_pairs) return pairs;
      pairs.emplace_back(poses[i], poses[i + gap]);
    }
  }
  return pairs;
}

struct PairMotion {
  int index = -1;               // into report.pairs
  Rigid3 flange;                // A = flange_i_from_flange_j
  Eigen::Matrix3d camera_rotation;  // R_B of cam_i_from_cam_j
  Eigen::Vector3d camera_direction;  // unit t_B
  bool translation = false;
};

// Kabsch: R minimising sum |a_k - R b_k|^2.
Eigen::Matrix3d Procrustes(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < a.size(); ++k) h += b[k] * a[k].transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * d * svd.matrixU().transpose();
}

// R_X from the pairs marked for rotation, refitted once without pairs beyond 3 robust sigmas (at least
// 0.5 deg). Returns the RMS residual (rad) and unmarks the rejected pairs.
double FitRotation(const std::vector<PairMotion>& motions, HandEyeStartReport* report, Eigen::Matrix3d* r_x) {
  double rms = 0;
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Vector3d> a, b;
    std::vector<int> used;
    for (size_t k = 0; k < motions.size(); ++k) {
      if (!report->pairs[motions[k].index].used_for_rotation) continue;
      a.push_back(LogSO3(motions[k].flange.rotation));
      b.push_back(LogSO3(motions[k].camera_rotation));
      used.push_back(static_cast<int>(k));
    }
    if (a.size() < 2) return -1;
    *r_x = Procrustes(a, b);
    std::vector<double> residuals;
    for (size_t k = 0; k < a.size(); ++k) residuals.push_back((a[k] - *r_x * b[k]).norm());
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = std::max(3.0 * 1.4826 * sorted[sorted.size() / 2], 0.5 * kPi / 180.0);
    double sum2 = 0;
    int kept = 0;
    for (size_t k = 0; k < residuals.size(); ++k) {
      if (round == 0 && residuals[k] > limit) {
        report->pairs[motions[used[k]].index].used_for_rotation = false;
      } else {
        sum2 += residuals[k] * residuals[k];
        ++kept;
      }
    }
    rms = kept > 0 ? std::sqrt(sum2 / kept) : -1;
  }
  return rms;
}

// t_X and the pair lengths by linear least squares; pairs whose length comes out negative (a two-view
// translation of the wrong sign) are dropped and the fit repeated.
bool FitTranslation(const std::vector<PairMotion>& motions, const Eigen::Matrix3d& r_x, HandEyeStartReport* report,
                    Eigen::Vector3d* t_x) {
  for (int round = 0; round < 3; ++round) {
    std::vector<int> used;
    for (size_t k = 0; k < motions.size(); ++k) {
      if (report->pairs[motions[k].index].used_for_translation) used.push_back(static_cast<int>(k));
    }
    const int m = static_cast<int>(used.size());
    if (m < 2) return false;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3 * m, 3 + m);
    Eigen::VectorXd rhs(3 * m);
    for (int k = 0; k < m; ++k) {
      const PairMotion& pm = motions[used[k]];
      a.block<3, 3>(3 * k, 0) = pm.flange.rotation - Eigen::Matrix3d::Identity();
      a.block<3, 1>(3 * k, 3 + k) = -(r_x * pm.camera_direction);
      rhs.segment<3>(3 * k) = -pm.flange.translation;
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(rhs);
    if (!x.allFinite()) return false;
    *t_x = x.head<3>();
    bool changed = false;
    for (int k = 0; k < m; ++k) {
      if (x[3 + k] <= 0) {
        report->pairs[motions[used[k]].index].used_for_translation = false;
        changed = true;
      }
    }
    if (!changed) return true;
  }
  return false;
}

// The flat-target solution over the identification poses, referenced to the one with the most dots; the
// index of each pose (into obs.poses) in the solution's views in *view_of.
void SolvePlane(const ObservationSet& obs, const HandEyeStartOptions& options, HandEyeStartReport* report,
                std::map<int, int>* view_of) {
  const std::vector<int> poses = obs.PosesWithRole(PoseRole::kIdentification);
  if (!options.try_plane || poses.size() < 3) return;
  std::vector<std::map<int, Eigen::Vector2d>> views;
  int reference = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    (*view_of)[poses[k]] = static_cast<int>(k);
    views.push_back(obs.poses[poses[k]].dots_px);
    if (views[k].size() > views[reference].size()) reference = static_cast<int>(k);
  }
  // A single tag (4-5 points, e.g. an AprilTag's corners and centre) has fewer dots than the plane asks of a
  // view by default (room for outliers): then every view must show the reference's dots, all of them.
  twoview::PlanarViewsOptions plane = options.plane;
  const int most = static_cast<int>(views[reference].size());
  if (most < plane.min_points && most >= 4) plane.min_points = most;
  report->plane = twoview::SolvePlanarViews(obs.camera, views, reference, plane);
  report->plane_reference = obs.poses[poses[reference]].id;
  if (report->plane->ok && report->plane->median_transfer_rms_px > options.max_plane_transfer_px) {
    report->plane->ok = false;
    report->plane->message += ": the dots are not on one plane";
  }
}

// Pair (i, j) from the flat-target solution: B = cam_i_from_cam_j, when both views are on the plane and
// the motion turns by the flange's angle.
bool PlanarPair(const HandEyeStartReport& report, const std::map<int, int>& view_of, int i, int j,
                const HandEyeStartOptions& options, HandEyePair* pair, PairMotion* pm) {
  if (!report.plane || !report.plane->ok) return false;
  const twoview::PlanarView& vi = report.plane->views[view_of.at(i)];
  const twoview::PlanarView& vj = report.plane->views[view_of.at(j)];
  if (!vi.ok || !vj.ok) return false;
  const Rigid3 b = vi.cam_from_ref * vj.cam_from_ref.Inverse();
  const double angle = RotationAngle(b.rotation);
  if (std::abs(angle - pair->flange_angle_rad) > options.max_angle_mismatch_rad) return false;
  pm->camera_rotation = b.rotation;
  const double length = b.translation.norm();
  pm->camera_direction = length > 0 ? Eigen::Vector3d(b.translation / length) : Eigen::Vector3d::Zero();
  pair->outcome = twoview::Outcome::kSuccess;
  pair->from_plane = true;
  pair->camera_angle_rad = angle;
  pair->used_for_rotation = pair->flange_angle_rad >= options.min_flange_angle_rad;
  pair->used_for_translation = length > 1e-3;  // in reference plane distances: 1 mm at 1 m
  return true;
}

}  // namespace

HandEyeStartReport StartHandEye(const ObservationSet& obs, const HandEyeStartOptions& options) {
  HandEyeStartReport report;
  report.fx_px = obs.camera.fx_px;
  if (!obs.UsesFlangePoses()) {
    report.message = "the hand-eye start needs a flange pose in every pose";
    return report;
  }
  const bool eye_to_hand = obs.robot.mount == CameraMount::kEyeToHand;
  std::vector<PairMotion> motions;
  std::vector<double> focal;
  std::map<int, int> view_of;
  SolvePlane(obs, options, &report, &view_of);
  // At the plane's f_x when it has one: the two-view fallback's focal prior, and the start's f_x.
  const bool plane_focal = report.plane && report.plane->ok && report.plane->fx_estimated;
  CameraIntrinsics camera = obs.camera;
  if (plane_focal) camera.fx_px = report.plane->fx_px;
  for (const auto& [i, j] : PairOrder(obs.PosesWithRole(PoseRole::kIdentification), options.max_pairs)) {
    const PoseObservation& pi = obs.poses[i];
    const PoseObservation& pj = obs.poses[j];
    HandEyePair pair;
    pair.pose_a = pi.id;
    pair.pose_b = pj.id;
    PairMotion pm;
    // Eye-to-hand the camera moves against the flange's points as flange_from_base does against the base:
    // A = (flange_from_base_i)^-1 * flange_from_base_j.
    pm.flange = eye_to_hand ? *pi.base_from_flange * pj.base_from_flange->Inverse()
                            : pi.base_from_flange->Inverse() * *pj.base_from_flange;
    pair.flange_angle_rad = RotationAngle(pm.flange.rotation);
    const Matches matches = MatchById(pi, pj);
    if (PlanarPair(report, view_of, i, j, options, &pair, &pm)) {
      // the flat-target solution's motion
    } else if (static_cast<int>(matches.dot_ids.size()) >= options.min_matches) {
      const twoview::TwoViewReport tv = twoview::EstimateTwoView(options.two_view, camera, matches.pixels_a, matches.pixels_b);
      pair.outcome = tv.outcome;
      const bool has_rotation = tv.outcome == twoview::Outcome::kSuccess || tv.outcome == twoview::Outcome::kAmbiguousPose ||
                                tv.outcome == twoview::Outcome::kPureRotation || tv.outcome == twoview::Outcome::kNoConvergence;
      if (has_rotation) {
        // The estimate is cam_j_from_cam_i: B = its inverse. Of an ambiguous pair's two solutions, the
        // one whose rotation angle is the flange's.
        Eigen::Matrix3d rotation = tv.rotation;
        Eigen::Vector3d direction = tv.translation_direction;
        if (tv.has_rival && std::abs(RotationAngle(tv.rival_rotation) - pair.flange_angle_rad) <
                                std::abs(RotationAngle(tv.rotation) - pair.flange_angle_rad)) {
          rotation = tv.rival_rotation;
          direction = tv.rival_translation_direction;
          pair.rival_chosen = true;
        }
        pm.camera_rotation = rotation.transpose();
        pm.camera_direction = -(rotation.transpose() * direction);
        pair.camera_angle_rad = RotationAngle(pm.camera_rotation);
        const bool angles_agree = std::abs(pair.camera_angle_rad - pair.flange_angle_rad) <= options.max_angle_mismatch_rad;
        pair.used_for_rotation = angles_agree && pair.flange_angle_rad >= options.min_flange_angle_rad;
        pair.used_for_translation = angles_agree && tv.translation_observable &&
                                    (tv.outcome == twoview::Outcome::kSuccess || tv.outcome == twoview::Outcome::kAmbiguousPose);
        if (tv.outcome == twoview::Outcome::kSuccess && tv.fx_observable && angles_agree) focal.push_back(tv.fx_px);
      }
    }
    pm.index = static_cast<int>(report.pairs.size());
    report.pairs.push_back(pair);
    if (pair.used_for_rotation || pair.used_for_translation) motions.push_back(pm);
  }
  Eigen::Matrix3d r_x;
  report.rotation_rms_rad = FitRotation(motions, &report, &r_x);
  if (report.rotation_rms_rad < 0) {
    report.message = "fewer than two pose pairs with a rotation of at least 2 deg whose camera motion, estimated from "
                     "the dots both images see, turns by the flange's angle: rotate the wrist more between poses";
    return report;
  }
  // A pair whose rotation disagrees with the fitted hand-eye rotation gives no trusted direction either.
  for (const PairMotion& pm : motions) {
    HandEyePair& pair = report.pairs[pm.index];
    if (pair.used_for_translation && pair.flange_angle_rad >= options.min_flange_angle_rad && !pair.used_for_rotation) {
      pair.used_for_translation = false;
    }
  }
  Eigen::Vector3d t_x;
  if (!FitTranslation(motions, r_x, &report, &t_x)) {
    report.message = "the hand-eye translation is not determined: too few pose pairs with an observable camera "
                     "translation, or only parallel rotation axes";
    return report;
  }
  for (const HandEyePair& p : report.pairs) {
    report.rotation_pairs += p.used_for_rotation ? 1 : 0;
    report.translation_pairs += p.used_for_translation ? 1 : 0;
  }
  if (plane_focal) {
    report.fx_px = report.plane->fx_px;
    report.fx_from_images = true;
  } else if (!focal.empty()) {
    std::nth_element(focal.begin(), focal.begin() + focal.size() / 2, focal.end());
    report.fx_px = focal[focal.size() / 2];
    report.fx_from_images = true;
  }
  (eye_to_hand ? report.base_from_cam : report.flange_from_cam) = Rigid3(r_x, t_x);
  report.ok = true;
  std::ostringstream msg;
  msg << "hand-eye start from " << report.rotation_pairs << " rotation and " << report.translation_pairs
      << " translation pairs of " << report.pairs.size() << ", rotation residual RMS "
      << report.rotation_rms_rad * 180.0 / kPi << " deg";
  if (report.plane && report.plane->ok) msg << "; flat target: " << report.plane->message;
  report.message = msg.str();
  return report;
}

}  // namespace selfcal::calibration

namespace selfcal::calibration {

HandEyeStartReport StartCameraFromImages(const ObservationSet& observations, const HandEyeStartOptions& options,
                                         Eigen::VectorXd* rho) {
  const RobotModel& robot = observations.robot;
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(robot);
  ObservationSet flange = observations;
  flange.robot.links.clear();
  flange.robot.limits.clear();
  for (PoseObservation& pose : flange.poses) {
    if (pose.joints_rad.size() != robot.num_joints()) {
      HandEyeStartReport report;
      report.message = "pose " + pose.id + " has no joint angle per joint";
      return report;
    }
    pose.base_from_flange = BaseFromFlange(robot, nominal, pose.joints_rad);
    pose.joints_rad.resize(0);
  }
  HandEyeStartReport report = StartHandEye(flange, options);
  if (!report.ok) return report;
  const Rigid3 correction = robot.mount == CameraMount::kEyeToHand ? robot.base_from_cam.Inverse() * report.base_from_cam
                                                                   : robot.flange_from_cam.Inverse() * report.flange_from_cam;
  const int cam = KinematicParameters(robot.num_joints()).CamOffset();
  rho->segment<3>(cam) = correction.translation;
  rho->segment<3>(cam + 3) = LogSO3(correction.rotation);
  return report;
}

}  // namespace selfcal::calibration
