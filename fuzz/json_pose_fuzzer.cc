// Fuzz harness: a per-image JSON pose file (docs/detect.md, io/json_pose_file.h) read three ways: by a 4x4
// matrix key (row-major), by joint angles on a 7-joint robot, and by position + quaternion. Any crash,
// sanitizer report, hang or uncaught exception is a defect; a refusal is the expected answer to a bad file
// and should name fuzz.json:<line>.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/json_pose_file.h"
#include "io/pose_files.h"
#include "kinematics/robot_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = selfcal::fuzz::WriteFuzzFile("fuzz.json", selfcal::fuzz::AsText(data, size));
  static const selfcal::RobotModel robot = [] {
    selfcal::RobotModel model;
    model.links.resize(7);
    return model;
  }();
  selfcal::io::JsonPoseKeys matrix, joints, position;
  matrix.matrix = "O_T_EE";
  joints.joints = "joint_pose";
  position.position = "p";
  position.quaternion = "q";
  for (const selfcal::io::JsonPoseKeys* keys : {&matrix, &joints, &position}) {
    selfcal::io::ImagePose pose;
    const selfcal::Status s = selfcal::io::LoadJsonPoseFile(path, *keys, &robot, &pose);
    if (!s.ok()) selfcal::fuzz::NoteRefusal("json_pose", s.message(), "fuzz.json:");
  }
  return 0;
}
