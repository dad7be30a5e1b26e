// Module detection (ARCHITECTURE.md): `selfcal detect`'s core, images in memory in. blob_candidates.h
// (the polarity, and the texture filter of blobs unlike the target's); circle_grid.h (grids without an origin
// dot through cv::findCirclesGrid) and grid_orientation.h (their rotation per image chosen from the robot
// poses); chessboard.h (cv::findChessboardCorners, ordered across images by handedness, the squares' colour and
// continuity); charuco.h (a ChArUco board named by its markers through OpenCV's aruco module, Debian's
// libopencv-contrib-dev, this module only); corner_refine.h (both refined along their edges); charuco_pattern.h
// (a ChArUco board's printed pattern and metric corners, the tests' reference and
// test/tools/selfcal_corner_precision's); contact_sheet.h (the contact sheet PNG in memory). No file I/O.
// Uses tracking, observations, kinematics, geometry, base, ViSP; OpenCV private.
//
// The points of a list of images, by id, for `selfcal detect` (docs/detect.md): images in memory in,
// per image the id -> pixel of every point named, and the ObservationSet of the images with their robot
// poses. No file I/O: the caller reads the images and poses (io/image_files.h, io/pose_files.h) and writes
// the result (io/observations_file.h).
//
// Detectors and identities:
//   dots + grid       tracking::DetectDots, then tracking::IdentifyGrid on a rows x cols modified circle
//                     grid (the larger dot marks the origin): id = row * cols + col, the same physical dot in
//                     every image (tracking/grid_identity.h);
//   dots + apriltag   tracking::DetectDots and tracking::DetectAprilTags: the dots laid out around every tag
//                     (positions in the tag's frame) named through the tag's homography, id = tag id *
//                     layout size + k (tracking/apriltag_identity.h). A dot two layout positions claim is
//                     given to neither;
//   dots + order      tracking::DetectDots: id = the dot's index in the detector's raster order. The same
//                     id names the same dot only when every image shows the dots in the same raster order
//                     (a nearly still camera); for anything else use grid or apriltag;
//   circles           a symmetric or asymmetric circle grid without an origin dot (detection/circle_grid.h):
//                     cv::findCirclesGrid on the dots, id = row * cols + col, its rotation in each image
//                     chosen from the robot poses afterwards (detection/grid_orientation.h);
//   chessboard        inner corners, ordered consistently (detection/chessboard.h): id = row * cols + col;
//   charuco           a ChArUco board's inner corners named by its ArUco markers (detection/charuco.h):
//                     OpenCV's ChArUco corner ids, the same physical corner in every image however much of
//                     the board is seen;
//   apriltag          the four outer corners of every AprilTag (tracking::DetectAprilTags, ViSP's detector):
//                     id = tag id * 4 + k, k = 0 bottom-left, 1 bottom-right, 2 top-right, 3 top-left (the tag's
//                     printed orientation, whatever its rotation in the image). The centre is not a point: its
//                     pixel is the diagonals' intersection, a function of the corners' pixels, not a measurement.
// Dots of either polarity (detection/blob_candidates.h): dark, light, or auto, per image the polarity whose
// grid (dots + grid, circles) is found, else (and when both are, or for apriltag and order) the one whose
// dots have the larger ContrastScore. Texture blobs are left out by ConsistentBlobs for circles and order
// (not for grid, whose origin dot is larger than the others by design, nor for apriltag).
// Pixels as tracking/dot_detector.h.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/progress.h"
#include "base/status.h"
#include "detection/blob_candidates.h"
#include "detection/charuco.h"
#include "detection/chessboard.h"
#include "geometry/rigid3.h"
#include "observations/observation_set.h"
#include "tracking/apriltag_identity.h"
#include "tracking/dot_detector.h"
#include "tracking/grid_identity.h"

namespace selfcal::detection {

enum class Detector { kDots, kCircles, kChessboard, kCharuco, kAprilTag };
enum class Identity { kGrid, kAprilTag, kOrder };
const char* DetectorName(Detector detector);
const char* IdentityName(Identity identity);
// "dots" / "circles" / "chessboard" / "charuco" / "apriltag", "grid" / "apriltag" / "order"; kInvalidInput otherwise.
Result<Detector> ParseDetector(const std::string& name);
Result<Identity> ParseIdentity(const std::string& name);

struct DetectionOptions {
  Detector detector = Detector::kDots;
  Identity identity = Identity::kGrid;  // dots only; a chessboard names its corners by the grid
  int rows = 10;  // dots + grid, circles: the dot grid; chessboard: inner corners; charuco: squares
  int cols = 10;
  bool asymmetric = false;  // circles: OpenCV's asymmetric grid (every other row shifted by half a step)
  tracking::DotDetectorOptions dots;
  Polarity polarity = Polarity::kDark;  // dots and circles
  BlobFilterOptions blob_filter;        // circles and dots + order
  tracking::GridIdentityOptions grid;  // rows and cols are taken from above
  tracking::AprilTagOptions apriltag;       // the apriltag identity and the apriltag detector
  double tag_side_m = 0;                    // apriltag: the black border's outer side (detector: optional)
  std::vector<Eigen::Vector2d> tag_dots_m;  // apriltag: the layout around every tag, (x, y) in its frame
  double tag_tolerance_px = 3.0;
  ChessboardOptions chessboard;  // rows and cols are taken from above
  CharucoOptions charuco;        // the dictionary; rows and cols (squares) are taken from above
  ProgressSink* progress = nullptr;  // DetectAllImagePoints: told each image done; null: nothing reported

  // Every problem, one per line (kInvalidInput).
  Status Validate() const;
};

struct ImagePoints {
  bool ok = false;
  std::string message;                     // why not (ok false), or how the ids were chosen
  std::map<int, Eigen::Vector2d> points_px;  // id -> pixel
  int candidates = 0;                      // dots detected (dots), corners found (chessboard), markers (charuco)
  Polarity polarity = Polarity::kDark;     // dots and circles: the polarity the points are of
};

// The points of one image. `previous` is the previous image's result (chessboard continuity), or nullptr.
// Throws InvalidArgument when the options are invalid.
ImagePoints DetectImagePoints(const vpImage<unsigned char>& image, const DetectionOptions& options,
                              const ImagePoints* previous);

// Every image in order (each chessboard image continues from the last image that was found).
std::vector<ImagePoints> DetectAllImagePoints(const std::vector<const vpImage<unsigned char>*>& images,
                                              const DetectionOptions& options);

// The apriltag detector's point ids: corner k (0 bottom-left ... 3 top-left) of tag `tag_id`.
inline int TagCornerId(int tag_id, int corner) { return 4 * tag_id + corner; }

// Known distances of the apriltag detector's corners, for every tag seen in `points` (in tag id order), of
// a tag of outer side `side_m`: the yardstick its bottom edge (corners 0-1), and the check distance its top
// edge (corners 3-2, no corner of the yardstick's: an independent check).
struct TagEdges {
  std::vector<KnownDistance> yardsticks, check_distances;
};
TagEdges TagEdgeDistances(const std::vector<ImagePoints>& points, double side_m);

// The robot pose of one image: the flange in the base frame, or the joint angles.
struct ImageRobotPose {
  std::optional<Rigid3> base_from_flange;
  Eigen::VectorXd joints_rad;
  PoseRole role = PoseRole::kIdentification;  // kVerification: held out from the solve
};

struct ObservationSetup {
  RobotModel robot;                    // nominal; for joint poses (a flange-pose set has FlangePoseModel)
  // Where the camera is; eye-to-hand: the camera fixed in the base frame, the points on the flange.
  CameraMount mount = CameraMount::kEyeInHand;
  // The nominal camera transform, when known: flange_from_cam (eye-in-hand, flange poses; a joint set's is
  // the robot's) or base_from_cam (eye-to-hand, for flange poses and joint angles alike).
  std::optional<Rigid3> flange_from_cam;
  std::optional<Rigid3> base_from_cam;
  CameraIntrinsics camera;             // nominal (width and height are the images')
  double pixel_noise_px = 0.5;
  // Flange poses: the stated noise of the recorded poses (0: exact); both or neither (ObservationSet).
  double flange_translation_sigma_m = 0, flange_rotation_sigma_rad = 0;
  std::vector<KnownDistance> yardsticks;
  std::vector<KnownDistance> check_distances;  // held out from the solve
  bool skip_failed = false;            // leave images without points out instead of refusing the set
};

// One pose per image, id `pose_ids[i]`, role robot_poses[i].role, with the image's points and robot pose: joint
// angles on setup.robot, or flange poses (every image, or none) on FlangePoseModel(flange_from_cam), with
// flange_from_cam_known when it was given; in eye-to-hand (setup.mount) the model's mount and base_from_cam,
// flange_from_cam_known when base_from_cam was given (ObservationSet). An image whose detection failed is refused (kDegenerateData
// naming the pose id and why) unless skip_failed; so is a set with no points; mixed flange and joint
// poses, and any set ObservationSet::Validate() refuses, are kInvalidInput.
Result<ObservationSet> BuildObservationSet(const std::vector<std::string>& pose_ids,
                                           const std::vector<ImagePoints>& points,
                                           const std::vector<ImageRobotPose>& robot_poses,
                                           const ObservationSetup& setup);

}  // namespace selfcal::detection
