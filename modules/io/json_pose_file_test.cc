// Recorded poses as controllers write them: rotations made rotations within the stated tolerance, JSON pose
// files by named keys, one folder per pose, and the tool frame.
#include "io/json_pose_file.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "io/file_lists.h"
#include "io/observations_file.h"
#include "io/pose_files.h"
#include "io/transform_yaml.h"
#include "io/io_test_util.h"

namespace selfcal::io {
namespace {

using testing::TempDir;
using testing::MessageHas;
using testing::WriteFile;

const Eigen::Matrix3d kRotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();

TEST(MakeRotation, ExactIsAsWrittenRoundedIsCorrectedFarIsRefused) {
  // Strict (files selfcal reads as written): 1e-9 passes unchanged, more is refused.
  Eigen::Matrix3d r = kRotation;
  r(0, 1) += 5e-10;
  RotationFromMatrix strict = MakeRotation(r, kExactRotationTolerance);
  ASSERT_TRUE(strict.ok);
  EXPECT_EQ(strict.rotation, r);
  EXPECT_EQ(strict.correction_rad, 0.0);
  // Recorded: a rotation orthonormal to 1e-12 as written; a 9-decimal or a float one is the nearest rotation,
  // orthonormal to the last bits, with a correction of the size of the disturbance.
  EXPECT_EQ(MakeRotation(kRotation, kRecordedRotationTolerance).rotation, kRotation);
  for (const double disturb : {5e-10, 2e-5, 5e-5}) {
    r = kRotation;
    r(0, 1) += disturb;
    const RotationFromMatrix recorded = MakeRotation(r, kRecordedRotationTolerance);
    ASSERT_TRUE(recorded.ok) << disturb << " " << recorded.problem;
    EXPECT_LT((recorded.rotation.transpose() * recorded.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 4e-15);
    EXPECT_NEAR(recorded.rotation.determinant(), 1.0, 4e-15);
    EXPECT_GT(recorded.correction_rad, 0.3 * disturb) << disturb;
    EXPECT_LT(recorded.correction_rad, disturb) << disturb;
    EXPECT_LT((recorded.rotation - kRotation).cwiseAbs().maxCoeff(), disturb);
  }
  r = kRotation;
  r(0, 1) += 1e-2;
  const RotationFromMatrix far = MakeRotation(r, kRecordedRotationTolerance);
  EXPECT_FALSE(far.ok);
  EXPECT_NE(far.problem.find("a rotation is orthonormal to 1e-04"), std::string::npos) << far.problem;
  const RotationFromMatrix mirror = MakeRotation(-kRotation, kRecordedRotationTolerance);
  EXPECT_FALSE(mirror.ok);
  EXPECT_NE(mirror.problem.find("reflection"), std::string::npos) << mirror.problem;
}

// The 16 numbers of a pose row by row, its rotation disturbed by `disturb` at (0, 1).
std::string MatrixJson(const Rigid3& pose, bool column_major, double disturb = 0) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = pose.rotation;
  m(0, 1) += disturb;
  m.topRightCorner<3, 1>() = pose.translation;
  std::string text = "{\n  \"joint_pose\": [0.1, 0.2],\n  \"O_T_EE\": [";
  for (int i = 0; i < 16; ++i) {
    char number[40];
    std::snprintf(number, sizeof(number), "%.17g", column_major ? m(i % 4, i / 4) : m(i / 4, i % 4));
    text += (i ? ", " : "") + std::string(number);
  }
  return text + "]\n}\n";
}

TEST(JsonPoseFile, MatrixRowOrColumnMajorPositionQuaternionAndJoints) {
  TempDir dir;
  const Rigid3 pose(kRotation, Eigen::Vector3d(0.4, -0.1, 0.3));
  JsonPoseKeys keys;
  keys.matrix = "O_T_EE";
  WriteFile(dir.File("row.json"), MatrixJson(pose, false));
  WriteFile(dir.File("column.json"), MatrixJson(pose, true));
  ImagePose read;
  ASSERT_TRUE(LoadJsonPoseFile(dir.File("row.json"), keys, nullptr, &read).ok());
  EXPECT_TRUE(read.base_from_flange->rotation.isApprox(pose.rotation, 1e-15));
  EXPECT_EQ(read.base_from_flange->translation, pose.translation);
  // Read the wrong way round, the last row is the translation: refused with the hint.
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("column.json"), keys, nullptr, &read),
                         dir.File("column.json") + ":3: `O_T_EE` read row-major has the last row (0.4, -0.1, 0.3, 1), "
                                                   "not (0, 0, 0, 1): is it stored column-major"));
  keys.column_major = true;
  ASSERT_TRUE(LoadJsonPoseFile(dir.File("column.json"), keys, nullptr, &read).ok());
  EXPECT_EQ(read.base_from_flange->translation, pose.translation);
  // libfranka's float output: made a rotation, the correction kept.
  keys.column_major = false;
  WriteFile(dir.File("float.json"), MatrixJson(pose, false, 2e-5));
  ASSERT_TRUE(LoadJsonPoseFile(dir.File("float.json"), keys, nullptr, &read).ok());
  EXPECT_GT(read.rotation_correction_rad, 1e-6);
  EXPECT_LT(read.rotation_correction_rad, 2e-5);
  WriteFile(dir.File("far.json"), MatrixJson(pose, false, 1e-2));
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("far.json"), keys, nullptr, &read),
                         dir.File("far.json") + ":3: the rotation of `O_T_EE` is not a rotation matrix"));
  // 4 rows of 4 are the same pose.
  WriteFile(dir.File("rows.json"), "{\"T\": [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 0.25], [0, 0, 0, 1]]}");
  keys.matrix = "T";
  ASSERT_TRUE(LoadJsonPoseFile(dir.File("rows.json"), keys, nullptr, &read).ok());
  EXPECT_EQ(read.base_from_flange->translation, Eigen::Vector3d(0.5, 0, 0.25));
  // Position and a quaternion w first.
  const Eigen::Quaterniond q(kRotation);
  char text[256];
  std::snprintf(text, sizeof(text), "{\"p\": [0.4, -0.1, 0.3], \"q\": [%.17g, %.17g, %.17g, %.17g]}", q.w(), q.x(), q.y(),
                q.z());
  WriteFile(dir.File("pq.json"), text);
  JsonPoseKeys pq;
  pq.position = "p";
  pq.quaternion = "q";
  pq.quaternion_wxyz = true;
  ASSERT_TRUE(LoadJsonPoseFile(dir.File("pq.json"), pq, nullptr, &read).ok());
  EXPECT_TRUE(read.base_from_flange->rotation.isApprox(kRotation, 1e-14));
  // Joints need the robot.
  JsonPoseKeys joints;
  joints.joints = "joint_pose";
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("row.json"), joints, nullptr, &read), "need the robot's config"));
}

TEST(JsonPoseFile, BadFilesNameFileLineAndKey) {
  TempDir dir;
  JsonPoseKeys keys;
  keys.matrix = "O_T_EE";
  ImagePose read;
  WriteFile(dir.File("15.json"), "{\n  \"a\": 1,\n  \"O_T_EE\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0]\n}\n");
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("15.json"), keys, nullptr, &read),
                         dir.File("15.json") + ":3: `O_T_EE` has 15 numbers; a 4x4 pose is 16 numbers (or 4 rows of 4)"));
  WriteFile(dir.File("text.json"), "{\"O_T_EE\": \"identity\"}");
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("text.json"), keys, nullptr, &read), "`O_T_EE` has a string"));
  WriteFile(dir.File("broken.json"), "{\"O_T_EE\": [1, 0,\n");
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("broken.json"), keys, nullptr, &read), dir.File("broken.json") + ":"));
  WriteFile(dir.File("other.json"), "{\"O_T_E\": []}");
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("other.json"), keys, nullptr, &read),
                         "no key `O_T_EE` (--pose-matrix-key); did you mean `O_T_E`?"));
  // A flange 48.9 m from the base: no arm's, and beyond what an observations file takes (10 m).
  WriteFile(dir.File("far.json"), "{\n  \"O_T_EE\": [1, 0, 0, 0.7, 0, 1, 0, 0, 0, 0, 1, 48.9, 0, 0, 0, 1]\n}\n");
  EXPECT_TRUE(MessageHas(LoadJsonPoseFile(dir.File("far.json"), keys, nullptr, &read),
                         dir.File("far.json") + ":2: `O_T_EE`'s translation (0.7, 0, 48.9) m is beyond 10 m"));
  JsonPoseKeys two;
  two.matrix = "a";
  two.joints = "b";
  EXPECT_TRUE(MessageHas(two.Validate(), "give exactly one of --pose-joints-key, --pose-matrix-key"));
}

// One folder per pose, read in the natural order of the folders' names (numbers by value, two recordings'
// folders each in one run); a tool pose becomes the flange's; a folder without its pose file is refused naming
// the folder.
TEST(PoseFolders, ReadAsStoredWithATool) {
  TempDir dir;
  const Rigid3 base_from_tool(kRotation, Eigen::Vector3d(0.4, -0.1, 0.3));
  for (const char* id : {"pose_10", "pose_2", "s3_pose_00", "s1_pose_11", "s1_pose_02"}) {
    std::filesystem::create_directories(dir.File(id));
    WriteFile(dir.File(std::string(id) + "/image.png"), "x");
    WriteFile(dir.File(std::string(id) + "/data.json"), MatrixJson(base_from_tool, false));
  }
  WriteFile(dir.File("calibration_result.json"), "{}");  // the recorder's own result beside the folders
  EXPECT_TRUE(IsPoseFolderDirectory(dir.path()));
  PoseReadOptions options;
  options.json.matrix = "O_T_EE";
  const Rigid3 flange_from_tool(RotationFromRpy(0, 0, DegToRad(-45)), Eigen::Vector3d(0, 0, 0.1034));
  options.flange_from_tool = flange_from_tool;
  Result<ImagesAndPoses> read = LoadImagesAndPoses(dir.path(), "", nullptr, options);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->ids, (std::vector<std::string>{"pose_2", "pose_10", "s1_pose_02", "s1_pose_11", "s3_pose_00"}));
  EXPECT_EQ(read->images[0], dir.File("pose_2/image.png"));
  const Rigid3 back = *read->poses[1].base_from_flange * flange_from_tool;
  EXPECT_TRUE(back.rotation.isApprox(base_from_tool.rotation, 1e-15));
  EXPECT_TRUE(back.translation.isApprox(base_from_tool.translation, 1e-15));
  EXPECT_TRUE(MessageHas(LoadImagesAndPoses(dir.path(), dir.File("elsewhere"), nullptr, options).status(),
                         "leave out --poses"));
  std::filesystem::remove(dir.File("pose_2/data.json"));
  EXPECT_TRUE(MessageHas(LoadImagesAndPoses(dir.path(), "", nullptr, options).status(),
                         dir.File("pose_2") + ": holds image.png as its image and none as its pose file"));
}

// An observations file's flange rotation written to 9 decimals is made a rotation and said in the notes; the
// rotations selfcal writes read back bit-identical, with no note.
TEST(ObservationsRotation, NineDecimalFlangeRotationIsCorrectedWithANote) {
  TempDir dir;
  const std::string head =
      "format: selfcal-observations\nversion: 1.1\ncamera: {width_px: 640, height_px: 480, fx_px: 600, cx_px: 319.5, "
      "cy_px: 239.5}\npixel_noise_px: 0.5\nyardsticks: []\nposes:\n";
  char rotation[256];
  std::snprintf(rotation, sizeof(rotation), "[[%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f]]",
                kRotation(0, 0), kRotation(0, 1), kRotation(0, 2), kRotation(1, 0), kRotation(1, 1), kRotation(1, 2),
                kRotation(2, 0), kRotation(2, 1), kRotation(2, 2));
  std::string text = head;
  for (int i = 0; i < 3; ++i) {
    text += "  - id: p" + std::to_string(i) + "\n    base_from_flange: {xyz_m: [0.4, 0, " + std::to_string(0.3 + 0.1 * i) +
            "], rotation: " + rotation + "}\n    dots: [[0, 300, 200], [1, 320, 210], [2, 330, 250]]\n";
  }
  WriteFile(dir.File("obs.yaml"), text);
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(dir.File("obs.yaml"));
  ASSERT_TRUE(doc.ok());
  std::vector<std::string> notes;
  Result<ObservationSet> set = ParseObservations(*doc, &notes);
  ASSERT_TRUE(set.ok()) << set.status().message();
  ASSERT_EQ(notes.size(), 3u);
  EXPECT_NE(notes[1].find(dir.File("obs.yaml") + ":11: pose p1: its rotation matrix was not orthonormal"),
            std::string::npos)
      << notes[1];
  ASSERT_TRUE(SaveObservations(*set, dir.File("again.yaml")).ok());
  Result<yaml::YamlDocument> again_doc = yaml::LoadYamlFile(dir.File("again.yaml"));
  ASSERT_TRUE(again_doc.ok());
  notes.clear();
  Result<ObservationSet> again = ParseObservations(*again_doc, &notes);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(again->poses[1].base_from_flange->rotation, set->poses[1].base_from_flange->rotation);
}

}  // namespace
}  // namespace selfcal::io
