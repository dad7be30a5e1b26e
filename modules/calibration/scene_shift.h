// Did the scene move before the verification images were taken? A refused held-out test whose verification
// images another recording took (a board bumped between sessions, another day) looks like a wrong model; but
// then one rigid move of the scene's points explains those images with the calibrated model's cameras held.
// SceneShiftOfVerification fits that move (6 parameters: a rotation about the points' centroid and a
// translation, by kinematics/damped_least_squares.h on the verification dots' reprojection) and reports the
// RMS before and after.
// The verdict's sentence names the move when the images would pass the held-out test after it
// (VerificationSceneMoved). A wrong model's errors can look like a move too (a link length wrong by millimetres
// shifts the dots of nearby configurations alike), so the sentence offers both readings.
#pragma once

#include <map>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct SceneShift {
  bool computed = false;      // false: no verification dot with a point, or the solve failed
  int poses = 0, dots = 0;    // verification images and dots used
  double rms_before_px = 0;   // RMS per coordinate with the points where the identification images put them
  double rms_after_px = 0;    // after the move
  double translation_m = 0;   // of the points' centroid
  double rotation_rad = 0;    // about it
  // The move: a point p goes to R (p - centre) + centre + t, t = move.head<3>() (m), R = Exp(move.tail<3>()).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 1> move = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Vector3d Moved(const Eigen::Vector3d& point) const;
};

// One dot of a pose whose point was solved: the pose's camera as the model puts it, the point, the pixel.
struct ShiftDot {
  Rigid3 cam_from_points;
  Eigen::Vector3d point;
  Eigen::Vector2d pixel;
};

// The dots of the poses pose_indices (into obs.poses) whose ids are among `points` (id -> position in the points'
// frame, bundle dots_in_base), each pose's camera from `robot` with parameters `rho`; *poses_seen (optional): how
// many of those poses have one.
std::vector<ShiftDot> ShiftDotsOf(const ObservationSet& obs, const std::vector<int>& pose_indices,
                                  const RobotModel& robot, const Eigen::VectorXd& rho,
                                  const std::map<int, Eigen::Vector3d>& points, int* poses_seen = nullptr);

// The move of the points that best explains `dots` seen by `camera`, their cameras held (centre: the centroid
// of their points); `poses` left 0.
SceneShift SceneShiftOfDots(const std::vector<ShiftDot>& dots, const CameraIntrinsics& camera);

// The mean squared residual per coordinate (px^2) of `dots` with the points moved by `shift`; a dot that does
// not project counts lost_px^2 per coordinate.
double MeanSquareAfter(const std::vector<ShiftDot>& dots, const CameraIntrinsics& camera, const SceneShift& shift,
                       double lost_px);

// SceneShiftOfDots over ShiftDotsOf(obs, pose_indices, ...), with `poses` set.
SceneShift SceneShiftOfPoses(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                             const Eigen::VectorXd& rho, const CameraIntrinsics& camera,
                             const std::map<int, Eigen::Vector3d>& points);

// SceneShiftOfPoses over the verification poses of `obs`.
SceneShift SceneShiftOfVerification(const ObservationSet& obs, const RobotModel& robot, const Eigen::VectorXd& rho,
                                    const CameraIntrinsics& camera, const std::map<int, Eigen::Vector3d>& points);

// The move explains the verification images: their RMS after it at least 3 times smaller, the held-out test's
// statistic scaled by (after / before)^2 within `chi_square_limit` (the refused `chi_square` as it would be
// after the move, to first order), and a move of at least 0.5 mm or 0.05 deg.
bool VerificationSceneMoved(const SceneShift& shift, double chi_square, double chi_square_limit);

}  // namespace selfcal::calibration
