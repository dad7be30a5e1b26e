// The robot pose of each image of a folder, in the forms people bring them (docs/detect.md), for
// `selfcal detect`:
//
//  (a) ROS-style, one YAML file per image (ROS-Industrial calibration data sets):
//        x: 0.71   y: 0.003   z: 0.85          # m
//        qx: -0.017  qy: 0.9997  qz: -0.014  qw: -0.002   # unit quaternion
//      the wrist (flange) in the robot base frame, base_from_flange;
//  (b) ViSP vpPoseVector, one YAML file per image (ViSP's hand-eye tutorials, rMe):
//        rows: 6
//        cols: 1
//        data: [[tx], [ty], [tz], [tux], [tuy], [tuz]]   # m, theta-u (axis * angle) rad
//  (c) a selfcal poses list, one file for all images:
//        format: selfcal-poses
//        version: 1
//        poses:
//          - {image: 0.png, base_from_flange: {xyz_m: [0.7, 0, 0.85], rotation: [[...], [...], [...]]}}
//          - {image: 1.png, joints_deg: [0, -30, 120, 0, 45, 0]}     # or joints_rad; needs a robot
//          - {image: 2.png, joints_deg: [5, -30, 120, 0, 45, 0], role: verification}
//      (base_from_flange in any form of io/transform_yaml.h; `role`, optional: identification (default)
//      or verification, an image held out from the solve to test the calibration);
//  (d) JSON, one file per image, the pose under keys the user names (io/json_pose_file.h).
// A rotation matrix is taken as controllers write it (kRecordedRotationTolerance of io/transform_yaml.h):
// made a rotation, the correction kept per pose for the caller to report. With a tool frame
// (PoseReadOptions::flange_from_tool) the recorded transforms are the tool's, base_from_tool, and become
// base_from_flange = base_from_tool * flange_from_tool^-1.
//
// The images and poses of `selfcal detect` come either as two lists (images, and poses of forms (a)-(d))
// or as one folder per pose (`DIR/<id>/image.png` + `DIR/<id>/data.json`: io/file_lists.h, PoseFolder).
//
// Images and poses are matched by ImageKey (io/file_lists.h) of their names: "franka_image-3.png" and
// "franka_pose_rPe_3.yaml" both have the key "3". Every problem names the file (and the line and key when
// there is one); the code is ErrorCode::kInvalidInput.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "geometry/rigid3.h"
#include "io/file_lists.h"
#include "io/json_pose_file.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

inline constexpr const char* kPosesListFormat = "selfcal-poses";
inline constexpr int kPosesListVersion = 1;

// A quaternion's norm may differ from 1 by this much (4-decimal files) before it is normalised.
inline constexpr double kQuaternionNormTolerance = 1e-3;

struct ImagePose {
  std::string key;     // ImageKey of the pose file, or of the list entry's `image`
  std::string source;  // "FILE" or "FILE:LINE", for messages
  std::optional<Rigid3> base_from_flange;
  Eigen::VectorXd joints_rad;  // empty unless a poses list gave joints
  bool verification = false;   // a poses list's `role: verification`
  double rotation_correction_rad = 0;  // how far the rotation as written was moved to a rotation (MakeRotation)
};

// How per-image pose files are read.
struct PoseReadOptions {
  JsonPoseKeys json;                       // the keys of JSON pose files (needed for them)
  std::optional<Rigid3> flange_from_tool;  // the recorded poses are of this tool frame (flange_from_tool, m)
};

// One per-image file of form (a) or (b), told apart by its keys (`rows`, `cols` or `data`: ViSP).
Result<Rigid3> LoadPerImagePoseFile(const std::string& path);

// A poses list (c). Joints are refused without `robot`; with it their count is checked (values outside its
// limits are kept: the controller's reading; calibrate names them).
Result<std::vector<ImagePose>> LoadPosesList(const std::string& path, const RobotModel* robot);

// A poses list entry with joint angles, for SavePosesList.
struct PosesListEntry {
  std::string image;           // the image's file name
  Eigen::VectorXd joints_rad;
  bool verification = false;   // written as `role: verification`
};

// Writes a poses list (c) of joint angles (joints_rad, numbers that read back bit-identical),
// atomically. kInvalidInput for an empty list, an empty image name or a non-finite joint.
Status SavePosesList(const std::vector<PosesListEntry>& entries, const std::string& path);

// One per-image pose file of any form: (d) by its extension `.json`, else (a) or (b). Its key and source are
// the file's; with options.flange_from_tool its transform is the tool's (made the flange's here).
Result<ImagePose> LoadPoseFile(const std::string& path, const RobotModel* robot, const PoseReadOptions& options);

// `spec` is a directory (every *.yaml / *.yml / *.json file in it is a per-image pose file), a glob of per-image
// pose files (`poses/pose_*.yaml`), or one poses list. Two files with one key are refused.
Result<std::vector<ImagePose>> LoadImagePoses(const std::string& spec, const RobotModel* robot,
                                              const PoseReadOptions& options = {});

// The images of `selfcal detect` with the pose of each, in order.
struct ImagesAndPoses {
  std::vector<std::string> images;  // image paths
  std::vector<std::string> ids;     // the pose ids: the image's file stem, or the pose's folder name
  std::vector<ImagePose> poses;
};
// `images_spec` is a folder-per-pose directory (io/file_lists.h; `poses_spec` then empty or the same
// directory), or images (ListFiles) whose poses `poses_spec` gives (LoadImagePoses, MatchPosesToImages).
Result<ImagesAndPoses> LoadImagesAndPoses(const std::string& images_spec, const std::string& poses_spec,
                                          const RobotModel* robot, const PoseReadOptions& options);

// The pose of every image, in the order of `image_paths`: an image without a pose, or a pose without an
// image, is refused, naming the image or the pose's file.
Result<std::vector<ImagePose>> MatchPosesToImages(const std::vector<std::string>& image_paths,
                                                  const std::vector<ImagePose>& poses);

}  // namespace selfcal::io
