#include "io/pose_files.h"

#include <filesystem>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <visp3/io/vpImageIo.h>

#include "io/file_lists.h"
#include "io/image_files.h"
#include "io/io_test_util.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using testing::TempDir;
using testing::MessageHas;
using testing::WriteFile;

TEST(FileLists, KeysAndStems) {
  EXPECT_EQ(ImageKey("a/b/franka_image-3.png"), "3");
  EXPECT_EQ(ImageKey("franka_pose_rPe_3.yaml"), "3");
  EXPECT_EQ(ImageKey("img_007.png"), "7");
  EXPECT_EQ(ImageKey("0.yaml"), "0");
  EXPECT_EQ(ImageKey("000.png"), "0");
  EXPECT_EQ(ImageKey("cam2_shot14.png"), "14");
  EXPECT_EQ(ImageKey("left.png"), "left");
  EXPECT_EQ(FileStem("dir.v2/x.tar.gz"), "x.tar");
}

TEST(FileLists, DirectoryAndGlobSortedByNumber) {
  TempDir dir;
  for (const char* name : {"10.png", "2.png", "1.PNG", "notes.txt", "3.yaml"}) WriteFile(dir.File(name), "x");
  Result<std::vector<std::string>> images = ListFiles(dir.path(), ImageExtensions(), "images");
  ASSERT_TRUE(images.ok()) << images.status().message();
  ASSERT_EQ(images->size(), 3u);
  EXPECT_EQ((*images)[0], dir.File("1.PNG"));
  EXPECT_EQ((*images)[1], dir.File("2.png"));
  EXPECT_EQ((*images)[2], dir.File("10.png"));
  Result<std::vector<std::string>> globbed = ListFiles(dir.File("*.yaml"), {".yaml"}, "pose files");
  ASSERT_TRUE(globbed.ok());
  EXPECT_EQ(globbed->size(), 1u);
  EXPECT_TRUE(MessageHas(ListFiles(dir.File("*.jpg"), ImageExtensions(), "images").status(), "no images found"));
}

constexpr char kRosPose[] =
    "x: 0.7169496300523684\ny: 0.00330346692205527\nz: 0.853313460465923\nqx: -0.01709391593413424\n"
    "qy: 0.99974825023776\nqz: -0.01437638468984423\nqw: -0.002133951223335981\n";

// kRosPose with its first `from` replaced by `to`.
std::string RosPoseWith(const std::string& from, const std::string& to) {
  std::string text = kRosPose;
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(PerImagePoseFile, RosQuaternionPose) {
  TempDir dir;
  WriteFile(dir.File("0.yaml"), kRosPose);
  Result<Rigid3> pose = LoadPerImagePoseFile(dir.File("0.yaml"));
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  const Eigen::Quaterniond q(-0.002133951223335981, -0.01709391593413424, 0.99974825023776, -0.01437638468984423);
  EXPECT_LT((pose->rotation - q.normalized().toRotationMatrix()).norm(), 1e-15);
  EXPECT_EQ(pose->translation, Eigen::Vector3d(0.7169496300523684, 0.00330346692205527, 0.853313460465923));
}

TEST(PerImagePoseFile, VispPoseVector) {
  TempDir dir;
  WriteFile(dir.File("p.yaml"),
            "rows: 6\ncols: 1\ndata: \n  - [0.335091]\n  - [-0.0321497]\n  - [0.30857]\n  - [-3.01226]\n"
            "  - [0.0236777]\n  - [-0.451343]\n");
  Result<Rigid3> pose = LoadPerImagePoseFile(dir.File("p.yaml"));
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  const Eigen::Vector3d tu(-3.01226, 0.0236777, -0.451343);
  const Eigen::AngleAxisd truth(tu.norm(), tu.normalized());
  EXPECT_LT((pose->rotation - truth.toRotationMatrix()).norm(), 1e-14);
  EXPECT_EQ(pose->translation, Eigen::Vector3d(0.335091, -0.0321497, 0.30857));
}

// Bad per-image files: each error names the file, the line and the key.
TEST(PerImagePoseFile, BadFilesNameFileLineAndKey) {
  TempDir dir;
  const std::string bad_key = dir.File("1.yaml");
  WriteFile(bad_key, RosPoseWith("qw:", "qq:"));
  const Status s = LoadPerImagePoseFile(bad_key).status();
  EXPECT_TRUE(MessageHas(s, "unknown key `qq` at " + bad_key + ":7"));
  EXPECT_TRUE(MessageHas(s, "missing required key `qw`"));
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);

  const std::string not_unit = dir.File("2.yaml");
  WriteFile(not_unit, RosPoseWith("qw: -0.002133951223335981", "qw: 0.5"));
  EXPECT_TRUE(MessageHas(LoadPerImagePoseFile(not_unit).status(), "quaternion (qx, qy, qz, qw) at " + not_unit + ":4 has norm"));

  const std::string short_visp = dir.File("3.yaml");
  WriteFile(short_visp, "rows: 6\ncols: 1\ndata:\n  - [0.1]\n  - [0.2]\n");
  EXPECT_TRUE(MessageHas(LoadPerImagePoseFile(short_visp).status(), "`data` at " + short_visp + ":4 must be a list of 6"));

  const std::string quoted = dir.File("4.yaml");
  WriteFile(quoted, "rows: 6\ncols: 1\ndata: [[0.1], [0.2], ['0.3'], [0], [0], [0]]\n");
  EXPECT_TRUE(MessageHas(LoadPerImagePoseFile(quoted).status(), quoted + ":3"));

  EXPECT_TRUE(MessageHas(LoadPerImagePoseFile(dir.File("missing.yaml")).status(), dir.File("missing.yaml")));
}

// A flange this far from the base is no arm's, and the observations file detect writes from it is refused by
// calibrate (`xyz_m` within 10 m): the pose file is refused at once, naming the line, the key and the value
// (the mutation campaign's ROS pose with z 0.853 -> 48.89 m, taken by detect before).
TEST(PerImagePoseFile, AFlangeBeyondTheReachOfAnArmIsRefusedByLine) {
  TempDir dir;
  const std::string far = dir.File("0.yaml");
  WriteFile(far, RosPoseWith("z: 0.853313460465923", "z: 48.891259886400817"));
  const Status s = LoadPerImagePoseFile(far).status();
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(MessageHas(s, "`z` = `48.891259886400817` at " + far + ":3 is out of range: must be in [-10, 10]"))
      << s.message();

  const std::string far_visp = dir.File("1.yaml");
  WriteFile(far_visp, "rows: 6\ncols: 1\ndata:\n  - [-10.5]\n  - [0]\n  - [0.3]\n  - [0]\n  - [0]\n  - [0]\n");
  EXPECT_TRUE(MessageHas(LoadPerImagePoseFile(far_visp).status(), far_visp + ":4")) << LoadPerImagePoseFile(far_visp).status().message();

  const std::string reach = dir.File("2.yaml");  // 10 m itself is taken, as in an observations file
  WriteFile(reach, RosPoseWith("x: 0.7169496300523684", "x: -10"));
  EXPECT_TRUE(LoadPerImagePoseFile(reach).ok()) << LoadPerImagePoseFile(reach).status().message();
}

constexpr char kPosesList[] =
    "format: selfcal-poses\n"
    "version: 1\n"
    "poses:\n"
    "  - image: img_01.png\n"
    "    base_from_flange: {xyz_m: [0.5, 0, 0.4], rpy_deg: [180, 0, 90]}\n"
    "  - image: img_02.png\n"
    "    base_from_flange: {xyz_mm: [500, 10, 400], rotation: [[1, 0, 0], [0, -1, 0], [0, 0, -1]]}\n";

TEST(PosesList, FlangePosesAndJoints) {
  TempDir dir;
  WriteFile(dir.File("poses.yaml"), kPosesList);
  Result<std::vector<ImagePose>> poses = LoadPosesList(dir.File("poses.yaml"), nullptr);
  ASSERT_TRUE(poses.ok()) << poses.status().message();
  ASSERT_EQ(poses->size(), 2u);
  EXPECT_EQ((*poses)[1].key, "2");
  ASSERT_TRUE((*poses)[1].base_from_flange.has_value());
  EXPECT_NEAR((*poses)[1].base_from_flange->translation.y(), 0.01, 1e-15);
  EXPECT_EQ((*poses)[1].source, dir.File("poses.yaml") + ":6");

  const RobotModel puma = selfcal::testing::Puma560();
  WriteFile(dir.File("joints.yaml"),
            "format: selfcal-poses\nversion: 1\nposes:\n  - {image: a1.png, joints_deg: [0, -30, -120, 0, 45, 0]}\n");
  Result<std::vector<ImagePose>> joints = LoadPosesList(dir.File("joints.yaml"), &puma);
  ASSERT_TRUE(joints.ok()) << joints.status().message();
  EXPECT_NEAR((*joints)[0].joints_rad[2], DegToRad(-120), 1e-15);
  EXPECT_FALSE((*joints)[0].base_from_flange.has_value());
  EXPECT_TRUE(MessageHas(LoadPosesList(dir.File("joints.yaml"), nullptr).status(), "need the robot's config"));
}

// SavePosesList writes what LoadPosesList reads back bit-identical, roles included; a bad role is named.
TEST(PosesList, WrittenJointListsReadBackWithTheirRoles) {
  TempDir dir;
  const RobotModel puma = selfcal::testing::Puma560();
  Eigen::VectorXd q(6);
  q << 0.1, -0.5235987755982988, -2.0943951023931957, 1e-17, 0.7853981633974483, -0.3;
  Eigen::VectorXd q2 = q;
  q2[2] = -3.3;  // both within the PUMA's limits
  const std::string path = dir.File("poses.yaml");
  ASSERT_TRUE(SavePosesList({{"frame_000000.png", q, false}, {"frame_000001.png", q2, true}}, path).ok());
  Result<std::vector<ImagePose>> poses = LoadPosesList(path, &puma);
  ASSERT_TRUE(poses.ok()) << poses.status().message();
  ASSERT_EQ(poses->size(), 2u);
  EXPECT_EQ((*poses)[0].key, "0");
  EXPECT_EQ((*poses)[1].key, "1");
  EXPECT_FALSE((*poses)[0].verification);
  EXPECT_TRUE((*poses)[1].verification);
  for (int j = 0; j < 6; ++j) {
    EXPECT_EQ((*poses)[0].joints_rad[j], q[j]);
    EXPECT_EQ((*poses)[1].joints_rad[j], q2[j]);
  }
  EXPECT_TRUE(MessageHas(SavePosesList({}, path), "at least one pose"));
  WriteFile(path, "format: selfcal-poses\nversion: 1\nposes:\n"
                  "  - {image: 1.png, joints_deg: [0, -30, -120, 0, 45, 0], role: verify}\n");
  EXPECT_TRUE(MessageHas(LoadPosesList(path, &puma).status(),
                         "`poses[0].role` = `verify` at " + path + ":4 must be identification or verification"));
}

TEST(PosesList, BadListsNameFileLineAndKey) {
  TempDir dir;
  const RobotModel puma = selfcal::testing::Puma560();
  const std::string path = dir.File("bad.yaml");
  WriteFile(path,
            "format: selfcal-poses\nversion: 1\nposes:\n"
            "  - {image: 1.png, base_from_flange: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}, joints_deg: [0, 0, 0, 0, 0, 0]}\n"
            "  - {image: 2.png}\n"
            "  - {image: 3.png, joints_deg: [0, 0, 0, 0, 0]}\n"
            "  - {image: 4.png, joints_deg: [0, 0, 0, 0, 0, 900]}\n"
            "  - {imag: 5.png, base_from_flange: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}}\n");
  const Status s = LoadPosesList(path, &puma).status();
  EXPECT_TRUE(MessageHas(s, "cannot load a poses list from " + path));
  EXPECT_TRUE(MessageHas(s, "pose `poses[0]` at " + path + ":4 must give exactly one of"));
  EXPECT_TRUE(MessageHas(s, "pose `poses[1]` at " + path + ":5 must give exactly one of"));
  EXPECT_TRUE(MessageHas(s, "poses[2].joints_deg"));
  EXPECT_TRUE(MessageHas(s, "poses[3].joints_deg[5]"));
  EXPECT_TRUE(MessageHas(s, "unknown key `imag` in `poses[4]` at " + path + ":8"));
  WriteFile(path, "format: selfcal-observations\nversion: 1\n");
  EXPECT_TRUE(MessageHas(LoadPosesList(path, nullptr).status(), "selfcal-poses"));
}

TEST(ImagePoses, DirectoryOfPerImageFilesMatchedToImages) {
  TempDir dir;
  std::filesystem::create_directories(dir.File("poses"));
  for (int i : {0, 1, 2}) WriteFile(dir.File("poses/pose_" + std::to_string(i) + ".yaml"), kRosPose);
  Result<std::vector<ImagePose>> poses = LoadImagePoses(dir.File("poses"), nullptr);
  ASSERT_TRUE(poses.ok()) << poses.status().message();
  ASSERT_EQ(poses->size(), 3u);
  Result<std::vector<ImagePose>> matched = MatchPosesToImages({"im/2.png", "im/0.png", "im/1.png"}, *poses);
  ASSERT_TRUE(matched.ok()) << matched.status().message();
  EXPECT_EQ((*matched)[0].source, dir.File("poses/pose_2.yaml"));
  // A glob of the same files.
  Result<std::vector<ImagePose>> globbed = LoadImagePoses(dir.File("poses/pose_*.yaml"), nullptr);
  ASSERT_TRUE(globbed.ok()) << globbed.status().message();
  EXPECT_EQ(globbed->size(), 3u);
  // A missing pose names the image; an extra pose names its file.
  const Status missing = MatchPosesToImages({"im/0.png", "im/1.png", "im/2.png", "im/3.png"}, *poses).status();
  EXPECT_TRUE(MessageHas(missing, "im/3.png: no pose for image number `3`"));
  const Status extra = MatchPosesToImages({"im/0.png", "im/1.png"}, *poses).status();
  EXPECT_TRUE(MessageHas(extra, dir.File("poses/pose_2.yaml") + ": a pose for image number `2`, but there is no such image"));
  const Status twice = MatchPosesToImages({"im/a1.png", "im/b1.png"}, *poses).status();
  EXPECT_TRUE(MessageHas(twice, "im/b1.png: has the same number `1` as im/a1.png"));
  // Two pose files for one image; a bad file in the directory.
  WriteFile(dir.File("poses/pose_01.yaml"), kRosPose);
  EXPECT_TRUE(MessageHas(LoadImagePoses(dir.File("poses"), nullptr).status(), "a second pose for image number `1`"));
  std::filesystem::remove(dir.File("poses/pose_01.yaml"));
  WriteFile(dir.File("poses/pose_3.yaml"), "x: 1\n");
  EXPECT_TRUE(MessageHas(LoadImagePoses(dir.File("poses"), nullptr).status(), dir.File("poses/pose_3.yaml")));
  EXPECT_TRUE(MessageHas(LoadImagePoses(dir.File("nothing"), nullptr).status(), dir.File("nothing")));
  EXPECT_TRUE(MessageHas(LoadImagePoses(dir.File("poses/pose_0.yaml"), nullptr).status(),
                         dir.File("poses/pose_0.yaml") + ": is the pose of one image; give the directory or a glob"));
}

TEST(ImageFiles, ReadsGreyAndRefusesBadOrMismatchedImages) {
  TempDir dir;
  vpImage<unsigned char> a(48, 64, 7), b(40, 64, 9);
  vpImageIo::write(a, dir.File("a.png"));
  vpImageIo::write(b, dir.File("b.png"));
  WriteFile(dir.File("c.png"), "not a png");
  Result<std::vector<NamedImage>> one = ReadGreyImages({dir.File("a.png")});
  ASSERT_TRUE(one.ok()) << one.status().message();
  EXPECT_EQ((*one)[0].image.getWidth(), 64u);
  EXPECT_EQ((*one)[0].image[3][5], 7);
  EXPECT_TRUE(MessageHas(ReadGreyImages({dir.File("a.png"), dir.File("b.png")}).status(),
                         dir.File("b.png") + ": is 64x40 px, but " + dir.File("a.png") + " is 64x48 px"));
  EXPECT_TRUE(MessageHas(ReadGreyImages({dir.File("a.png"), dir.File("c.png")}).status(), dir.File("c.png") + ": cannot"));
  EXPECT_TRUE(MessageHas(ReadGreyImages({dir.File("none.png")}).status(), dir.File("none.png") + ": not a readable"));
}

}  // namespace
}  // namespace selfcal::io
