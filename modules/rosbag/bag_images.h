// Module rosbag (ARCHITECTURE.md): ROS 2 recordings for `selfcal detect --bag`: mcap_reader.h (an MCAP file
// scanned record by record from the specification, zstd chunks through libzstd, every length checked,
// refusals naming the byte offset), ros_messages.h (JointState, Image, CompressedImage from CDR; images made
// grey with ViSP's conversions, compressed ones decoded by OpenCV), this header (joints by the URDF robot's
// names through io). Uses io, base, ViSP; libzstd and OpenCV private.
//
// A ROS 2 recording (a rosbag2 MCAP file) as the images and joint angles of `selfcal detect --bag`
// (docs/detect.md, "ROS 2 recordings"): the joint states of one topic (sensor_msgs/msg/JointState) and the
// images of another (sensor_msgs/msg/Image or CompressedImage), each image kept only when the arm was still
// around it and given the joint reading nearest in time.
//
//  * Times: every message's header stamp (the message's log time when its stamp is zero).
//  * Still: the joint readings within still_window_s before and after the image's stamp include one at
//    least half the window before it and one at least half the window after it, and no joint's position
//    over them spans more than still_tolerance_rad. An image taken while moving is left out (counted).
//  * Matched: the joint reading nearest in time to the image, within match_tolerance_s; a still image
//    without one is left out with a note.
//  * Joint order: a robot whose config names its joints (a URDF robot) takes each joint by name from
//    every joint state (other joints in the message, a gripper's, are ignored; a missing one is refused);
//    otherwise the message's order, its joint count equal to the robot's, with a note saying so.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "io/image_files.h"
#include "io/pose_files.h"
#include "kinematics/robot_model.h"

namespace selfcal::rosbag {

struct BagOptions {
  std::string joint_topic = "/joint_states";
  std::string image_topic;            // required
  double still_window_s = 0.2;        // the readings looked at either side of an image
  double still_tolerance_rad = 1e-4;  // the largest span of a joint's position over them
  double match_tolerance_s = 0.05;    // the nearest reading at most this far from the image
};

// One joint reading, in the robot's joint order.
struct JointSample {
  double time_s = 0;
  Eigen::VectorXd position_rad;
};

// Which of the images at `image_times_s` were taken while still, and the index in `joints` (sorted by
// time) of each one's nearest reading (-1: left out). `notes` gets a line per still image left out for
// want of a near reading. Pure: the rule above, for the tests.
std::vector<int> MatchStillImages(const std::vector<JointSample>& joints, const std::vector<double>& image_times_s,
                                  const BagOptions& options, int* moving, std::vector<std::string>* notes);

struct BagImages {
  io::ImagesAndPoses inputs;             // images: "BAG:TOPIC#N" names; ids "image_NNNN"; poses: joints_rad
  std::vector<io::NamedImage> images;    // the grey images, in the same order
  std::vector<std::string> notes;        // for stderr: the joint order used, images left out
  int image_messages = 0, moving = 0;    // the topic's images, and how many were taken while moving
};

// The still images of `bag` with their joint angles for a robot of `dof` joints; `joint_names`, when not
// empty, the robot's joints by name in its order. ErrorCode::kInvalidInput naming the file (and the byte
// offset of the message) for a file MCAP refuses, a topic absent or of another type, a joint missing
// from a joint state, images of different sizes, no still image.
Result<BagImages> LoadBagImages(const std::string& bag, const BagOptions& options, int dof,
                                const std::vector<std::string>& joint_names);

// The same for the robot of the config at `robot_config` (already loaded as `robot`): its joint names when
// the config names them (io/robot_origin.h: a URDF robot), else the message's order.
Result<BagImages> LoadBagImagesForRobot(const std::string& bag, const BagOptions& options,
                                        const std::string& robot_config, const RobotModel& robot);

}  // namespace selfcal::rosbag
