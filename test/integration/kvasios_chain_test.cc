// A full kinematic self-calibration of a real arm with the default options: the kvasios Franka Panda
// recordings of test/data/kvasios-franka-handeye (real joint angles, a RealSense wrist camera, a static
// ChArUco board whose 24 inner corners are the unknown points, the board's geometry withheld except one
// yardstick: corners 5-18, 198.252 mm). Joint 3 stays within 0.5 deg in every session, so j2.d and j4.d
// cannot be told apart; the shipped Panda camera mount is 44 deg from this cell's camera. With the defaults
// the calibration must converge, name what the data cannot determine and hold it at the robot description,
// and start the camera from the images. `detect` reads each session's one-folder-per-pose layout as stored.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunSelfcalInSource;

const fs::path kData = fs::path(SELFCAL_SOURCE_DIR) / "test/data/kvasios-franka-handeye";

// detect on one session as it is stored (a folder per pose, the joints under `joint_pose`): the
// observations file's path.
std::string Detect(const std::string& session, const fs::path& dir, const std::string& noise_px = "0.5") {
  fs::create_directories(dir);
  const std::string obs = (dir / "obs.yaml").string();
  std::string output;
  const int code = RunSelfcalInSource(
      "detect --images " + (kData / session).string() +
          " --pose-joints-key joint_pose --robot config/robots/panda.yaml --detector chessboard --grid 4x6 --camera-file " +
          (kData / "realsense_factory.yaml").string() + " --yardstick 5,18,198.252 --pixel-noise-px " + noise_px + " --out " + obs,
      &output);
  EXPECT_EQ(code, 0) << output;
  return obs;
}

// An observations file's text split into its head (robot, camera, yardstick) and its pose blocks, each
// starting at `  - id: "pose_NN"`.
std::vector<std::string> PoseBlocks(const std::string& text, std::string* head) {
  std::vector<std::string> out;
  size_t at = text.find("  - id: ");
  *head = text.substr(0, at);
  while (at != std::string::npos) {
    const size_t next = text.find("  - id: ", at + 1);
    out.push_back(text.substr(at, next == std::string::npos ? std::string::npos : next - at));
    at = next;
  }
  return out;
}

// A pose block of another session for a combined file: its id prefixed with `prefix` and `_`, made a
// verification pose when asked, and given `scene:` (after its role line) when `scene` is not empty.
std::string Relabel(std::string block, const std::string& prefix, bool verification, const std::string& scene = "") {
  block.replace(block.find("id: \"") + 5, 0, prefix + "_");
  if (verification) block.replace(block.find("role: identification"), 20, "role: verification");
  const size_t role_end = block.find('\n', block.find("role: ")) + 1;
  if (!scene.empty()) block.insert(role_end, "    scene: " + scene + "\n");
  return block;
}

TEST(KvasiosChain, EverySessionCalibratesWithTheDefaultsNamingWhatTheDataCannotDetermine) {
  for (const std::string session : {"s1", "s2", "s3"}) {
    const fs::path dir = FreshDir("kvasios", session);
    const std::string obs = Detect(session, dir);
    std::string output;
    const int code = RunSelfcalInSource("calibrate " + obs + " --out " + (dir / "cal").string() + " --no-html", &output);
    EXPECT_EQ(code, 0) << session << "\n" << output;
    std::ifstream in(dir / "cal" / "report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    const nlohmann::json& bundle = report.at("methods").at("bundle");
    EXPECT_EQ(bundle.at("outcome"), "converged") << session;
    // Joint 3 barely moves, and the offsets beside it are held at the description, named in the output.
    const nlohmann::json& weak = bundle.at("weak");
    ASSERT_EQ(weak.at("barely_moving_joints").size(), 1u) << weak.dump();
    EXPECT_EQ(weak.at("barely_moving_joints")[0].at("joint"), 3);
    EXPECT_LT(weak.at("barely_moving_joints")[0].at("range_deg").get<double>(), 1.0);
    bool j4d = false;
    for (const nlohmann::json& held : weak.at("held")) {
      EXPECT_GT(held.at("conditional_std").get<double>(), held.at("tolerance").get<double>()) << held.dump();
      j4d = j4d || held.at("name") == "j4.d";
    }
    EXPECT_TRUE(j4d) << weak.dump();
    EXPECT_NE(output.find("joint 3 barely moves"), std::string::npos) << output;
    EXPECT_NE(output.find("held (weak): j4.d"), std::string::npos) << output;
    // No verification poses: the held-out figure of 4 folds of the session's own poses, every pose held out
    // once; within the goal set for another session's poses (1.2 px per coordinate).
    const nlohmann::json& cv = report.at("cross_validation");
    ASSERT_TRUE(cv.at("ran").get<bool>()) << cv.dump();
    EXPECT_EQ(cv.at("per_fold").size(), 4u);
    EXPECT_GT(cv.at("num_residuals").get<int>(), 12 * 24 - 12) << cv.dump();
    EXPECT_LT(cv.at("rms_px").get<double>(), 1.2) << cv.dump();
    // The folds' pooled held-out test is the verdict's: made, and passed.
    bool cv_test = false;
    for (const nlohmann::json& check : report.at("acceptance")) {
      cv_test = cv_test || (check.at("check") == "cross_validation_test" && check.at("status") == "passed");
    }
    EXPECT_TRUE(cv_test) << report.at("acceptance").dump();
    EXPECT_NE(output.find("cross-validation (4 folds"), std::string::npos) << output;
    // The yardstick is also a check: against the Panda description's link lengths (measured 0.9969 +- 0.0030,
    // 0.9980 +- 0.0032, 0.9991 +- 0.0055 for s1, s2, s3).
    EXPECT_NE(output.find("passed: the yardstick agrees with the robot description"), std::string::npos) << output;
    // The camera's start came from the images, not from the shipped mount 44 deg away.
    EXPECT_NE(bundle.at("start_note").get<std::string>().find("camera correction from the images"), std::string::npos)
        << bundle.at("start_note");
  }
}

// A yardstick typed wrong (198.252 mm as 189.3 mm) scales the whole arm and changes no image: the held-out
// tests pass (0.65 px), every correction looks plausible (18 mm at most), and only the description's lengths
// tell. Refused (exit 6) naming the yardstick and the factor, no model written.
TEST(KvasiosChain, AYardstickTypedWrongIsRefusedAgainstTheDescriptionsLengths) {
  const fs::path dir = FreshDir("kvasios", "typo");
  std::ifstream in(Detect("s1", dir));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string right = "length_m: 0.198252";
  const size_t at = text.find(right);
  ASSERT_NE(at, std::string::npos) << text.substr(0, 2000);
  text.replace(at, right.size(), "length_m: 0.1893");
  const fs::path typo = dir / "typo.yaml";
  std::ofstream(typo) << text;
  std::string output;
  EXPECT_EQ(RunSelfcalInSource("calibrate " + typo.string() + " --out " + (dir / "cal").string() + " --no-html", &output),
            6)
      << output;
  EXPECT_NE(output.find("the yardstick disagrees with the robot description"), std::string::npos) << output;
  // The right yardstick's factor (0.9969) times 189.3 / 198.252: 0.9519.
  EXPECT_NE(output.find("j7.a) 0.9519 +- 0.00"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "cal" / "calibrated_model.yaml"));
}

// Sessions s1 and s3 (recorded the next day, the board moved by about 7 mm and 2 deg) pooled as they are:
// each file a scene of its own, one arm calibrated from both, the move measured and named; s1 with s2 (the
// same day, the board unmoved) shows no move beyond the points' scatter.
TEST(KvasiosChain, RecordingsPooledEachAsItsSceneNameTheBoardThatMoved) {
  const fs::path dir = FreshDir("kvasios", "pooled");
  const std::string s1 = Detect("s1", dir / "s1"), s2 = Detect("s2", dir / "s2"), s3 = Detect("s3", dir / "s3");
  // Each scene is named by its file's name: give the copies their sessions' names.
  fs::copy_file(s1, dir / "s1.yaml");
  fs::copy_file(s2, dir / "s2.yaml");
  fs::copy_file(s3, dir / "s3.yaml");
  std::string output;
  int code = RunSelfcalInSource("calibrate " + (dir / "s1.yaml").string() + " --also " + (dir / "s3.yaml").string() +
                                    " --out " + (dir / "cal13").string() + " --no-html",
                                &output);
  EXPECT_EQ(code, 0) << output;
  std::ifstream in13(dir / "cal13" / "report.json");
  const nlohmann::json moved = nlohmann::json::parse(in13).at("scene_moves");
  ASSERT_EQ(moved.size(), 1u) << moved.dump();
  EXPECT_EQ(moved[0].at("scene"), "s3");
  EXPECT_EQ(moved[0].at("relative_to"), "s1");
  EXPECT_EQ(moved[0].at("shared_points").get<int>(), 24);
  EXPECT_TRUE(moved[0].at("moved").get<bool>()) << moved.dump();
  EXPECT_GT(moved[0].at("displacement_rms_m").get<double>(), 10 * moved[0].at("rigid_fit_rms_m").get<double>()) << moved.dump();
  EXPECT_LT(moved[0].at("displacement_rms_m").get<double>(), 0.012) << moved.dump();
  EXPECT_NEAR(moved[0].at("rotation_rad").get<double>() * 180 / M_PI, 2.1, 0.6) << moved.dump();
  EXPECT_NE(output.find("scene `s3` against `s1`"), std::string::npos) << output;
  EXPECT_NE(output.find("the scene moved"), std::string::npos) << output;

  code = RunSelfcalInSource("calibrate " + (dir / "s1.yaml").string() + " --also " + (dir / "s2.yaml").string() +
                                " --out " + (dir / "cal12").string() + " --no-html",
                            &output);
  EXPECT_EQ(code, 0) << output;
  std::ifstream in12(dir / "cal12" / "report.json");
  const nlohmann::json still = nlohmann::json::parse(in12).at("scene_moves");
  ASSERT_EQ(still.size(), 1u) << still.dump();
  EXPECT_FALSE(still[0].at("moved").get<bool>()) << still.dump();
}

// Without verification poses and without the cross-validation nothing held images out: the model is
// written, and the verdict, the exit code and the model's provenance say it is untested.
TEST(KvasiosChain, AModelNoHeldOutTestCouldCheckIsWrittenAsUntested) {
  const fs::path dir = FreshDir("kvasios", "untested");
  const std::string obs = Detect("s1", dir);
  std::string output;
  const int code = RunSelfcalInSource("calibrate " + obs + " --folds 0 --out " + (dir / "cal").string() + " --no-html", &output);
  EXPECT_EQ(code, 8) << output;
  EXPECT_NE(output.find("untested: "), std::string::npos) << output;
  std::ifstream in(dir / "cal" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report.at("verdict"), "untested");
  EXPECT_EQ(report.at("accepted"), false);
  EXPECT_EQ(report.at("exit_code"), 8);
  std::ifstream model(dir / "cal" / "calibrated_model.yaml");
  const std::string text((std::istreambuf_iterator<char>(model)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"verdict\": \"untested\""), std::string::npos) << text.substr(0, 2000);
}

// s1's pose_03 has a misdetected corner (dot 0, 6 px off; the fit's screen leaves it out when the pose is
// fitted). Held out with pose_00 and pose_02 at a stated 0.15 px, it is left out of the held-out test and
// named, and the rest is explained by the error model estimated from the fit's own residuals (0.06 px and
// each image's pose error). Tested against its own covariance, the corner hid in a held parameter's
// tolerance and refused the model alone (chi-square 6953 over 144 at the estimate, 1276 at the stated noise).
TEST(KvasiosChain, AMisdetectedCornerInAHeldOutPoseIsLeftOutAndTheEstimatedErrorModelHolds) {
  const fs::path dir = FreshDir("kvasios", "gross");
  std::ifstream in(Detect("s1", dir, "0.15"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* id : {"\"pose_00\"", "\"pose_02\"", "\"pose_03\""}) {
    const size_t role = text.find("role: identification", text.find(id));
    ASSERT_NE(role, std::string::npos) << id;
    text.replace(role, 20, "role: verification");
  }
  std::ofstream((dir / "held.yaml").string()) << text;
  std::string output;
  EXPECT_EQ(RunSelfcalInSource("calibrate " + (dir / "held.yaml").string() + " --out " + (dir / "cal").string() +
                                   " --no-html",
                               &output),
            0)
      << output;
  std::ifstream report_file(dir / "cal" / "report.json");
  const nlohmann::json heldout = nlohmann::json::parse(report_file).at("heldout_reprojection").at("calibrated_model");
  bool named = false;
  for (const nlohmann::json& e : heldout.at("gross_errors")) {
    named = named || (e.at("pose") == "pose_03" && e.at("dot") == 0);
  }
  EXPECT_TRUE(named) << heldout.at("gross_errors").dump();
  EXPECT_LE(heldout.at("gross_errors").size(), 3u);  // 5 % of 72
  EXPECT_TRUE(heldout.at("overall").at("test_passed")) << heldout.at("overall").dump();
  EXPECT_TRUE(heldout.at("overall_at_stated_noise").at("test_passed")) << heldout.at("overall_at_stated_noise").dump();
}

// Fold 0 of the cross-session protocol: s1 without the targets 0, 4 and 8 as identification poses, those
// targets of `session` as verification poses, calibrated with the defaults under `dir`: its report.json.
nlohmann::json CalibrateFold0(const std::string& session, const fs::path& dir, std::string* output) {
  std::ifstream s1(Detect("s1", dir / "s1")), other(Detect(session, dir / session));
  std::string train((std::istreambuf_iterator<char>(s1)), std::istreambuf_iterator<char>());
  std::string test((std::istreambuf_iterator<char>(other)), std::istreambuf_iterator<char>());
  std::string head, ignored;  // the file's head is s1's
  const std::vector<std::string> train_poses = PoseBlocks(train, &head);
  const std::vector<std::string> test_poses = PoseBlocks(test, &ignored);
  EXPECT_EQ(train_poses.size(), 12u);
  EXPECT_EQ(test_poses.size(), 12u);
  std::string combined = head;
  for (std::size_t n = 0; n < train_poses.size(); ++n) {
    if (n % 4 != 0) combined += train_poses[n];
  }
  for (std::size_t n = 0; n < test_poses.size(); n += 4) combined += Relabel(test_poses[n], session, true);
  const fs::path obs = dir / "fold0.yaml";
  std::ofstream(obs) << combined;
  RunSelfcalInSource("calibrate " + obs.string() + " --out " + (dir / "cal").string() + " --no-html", output);
  std::ifstream in(dir / "cal" / "report.json");
  return nlohmann::json::parse(in);
}

// Calibrated on s1 without the targets 0, 4 and 8, the model predicts those targets in s2 (recorded the same
// day, the board unmoved) from their joint angles alone. The nominal Panda with OpenCV's hand-eye and the
// known board predicts them at 4.15 px RMS per coordinate; the goal for a self-calibration is 1.2 px.
TEST(KvasiosChain, ACalibrationOnOneSessionPredictsAnotherSessionsHeldOutTargets) {
  std::string output;
  const nlohmann::json report = CalibrateFold0("s2", FreshDir("kvasios", "crossval"), &output);
  const nlohmann::json& heldout = report.at("heldout_reprojection");
  const double rms = heldout.at("calibrated_model").at("overall").at("rms_px").get<double>();
  // s2's pose_04 has one corner 7.4 px off its prediction (a detection error, the other 23 within 0.9 px): the
  // held-out test leaves it out and names it.
  const nlohmann::json& gross = heldout.at("calibrated_model").at("gross_errors");
  EXPECT_EQ(heldout.at("calibrated_model").at("overall").at("num_residuals").get<int>() + gross.size(), 3u * 24) << output;
  EXPECT_LE(gross.size(), 1u) << gross.dump();
  EXPECT_LT(rms, 1.2) << output;
  // With the cell's error model estimated (pose error beside the pixel noise) the held-out test passes.
  EXPECT_EQ(report.at("verdict").get<std::string>(), "accepted") << output;
}

// The same targets in s3 (the board moved overnight): refused, and the refusal names a move of the scene of
// about 3 mm and 2.1 deg (as `calibrate s1 --also s3` measures it) as what would explain them.
TEST(KvasiosChain, AnotherDaysSessionAsVerificationIsRefusedAndTheMoveOfItsBoardNamed) {
  std::string output;
  const nlohmann::json report = CalibrateFold0("s3", FreshDir("kvasios", "moved"), &output);
  EXPECT_EQ(report.at("verdict").get<std::string>(), "rejected") << output;
  const std::string reasons = report.at("reasons").dump();
  const std::size_t at = reasons.find("one move of the scene would explain the verification images");
  ASSERT_NE(at, std::string::npos) << reasons;
  double mm = 0, deg = 0;
  const std::size_t points = reasons.find("its points ", at);
  ASSERT_NE(points, std::string::npos) << reasons;
  ASSERT_EQ(std::sscanf(reasons.c_str() + points, "its points %lf mm and %lf deg", &mm, &deg), 2) << reasons;
  EXPECT_GT(mm, 2.0);
  EXPECT_LT(mm, 4.5);
  EXPECT_NEAR(deg, 2.09, 0.3);
}

// s3 was recorded the next day after the board moved by about 7 mm and 2.1 deg. With a scene each (`scene:` per
// pose) s1 + s3 calibrate one arm together and predict s2's targets 0, 4 and 8 (s1's board) from their joints
// alone, within the 1.2 px goal. Pooled as one scene, with no scene named (two recordings copied into one
// file), the calibration finds the two places of the board itself (scene_split.h): exactly s3's poses see it
// elsewhere, by about the move the named scenes measure, and the solve with a scene each is the result, as
// good as with the scenes named.
TEST(KvasiosChain, TwoRecordingsOfAMovedBoardCalibrateTogetherWithASceneEach) {
  const fs::path dir = FreshDir("kvasios", "scenes");
  std::string heads[3];
  const char* sessions[3] = {"s1", "s3", "s2"};
  std::vector<std::string> blocks[3];
  for (int s = 0; s < 3; ++s) {
    std::ifstream in(Detect(sessions[s], dir / sessions[s]));
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    blocks[s] = PoseBlocks(text, &heads[s]);
    ASSERT_EQ(blocks[s].size(), 12u);
  }
  auto pose = [&](int s, int n, const std::string& scene, bool verification) {
    return Relabel(blocks[s][n], sessions[s], verification, scene);
  };
  double rms[2];
  for (int separate = 0; separate < 2; ++separate) {
    std::string combined = heads[0];
    for (int n = 0; n < 12; ++n) combined += pose(0, n, separate ? "s1" : "", false);
    for (int n = 0; n < 12; ++n) combined += pose(1, n, separate ? "s3" : "", false);
    for (int n = 0; n < 12; n += 4) combined += pose(2, n, separate ? "s1" : "", true);
    const fs::path obs = dir / (separate ? "scenes.yaml" : "one.yaml");
    std::ofstream(obs) << combined;
    std::string output;
    const fs::path out = dir / (separate ? "cal-scenes" : "cal-one");
    RunSelfcalInSource("calibrate " + obs.string() + " --out " + out.string() + " --no-html", &output);
    std::ifstream in(out / "report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    EXPECT_EQ(report.at("methods").at("bundle").at("outcome"), "converged") << output;
    rms[separate] = report.at("heldout_reprojection").at("calibrated_model").at("overall").at("rms_px").get<double>();
    if (separate) {
      EXPECT_NE(output.find("scenes: 2"), std::string::npos) << output;
      EXPECT_TRUE(report.at("scene_split").is_null()) << output;
    } else {
      const nlohmann::json& split = report.at("scene_split");
      ASSERT_TRUE(split.at("found").get<bool>()) << output;
      EXPECT_TRUE(split.at("applied").get<bool>()) << output;
      std::vector<std::string> s3_poses;
      for (int n = 0; n < 12; ++n) {
        char id[16];
        std::snprintf(id, sizeof id, "s3_pose_%02d", n);
        s3_poses.push_back(id);
      }
      EXPECT_EQ(split.at("second_poses").get<std::vector<std::string>>(), s3_poses) << output;
      EXPECT_EQ(split.at("first_poses").size(), 15u) << output;
      EXPECT_NE(output.find("the scene moved between poses"), std::string::npos) << output;
      const nlohmann::json& move = report.at("scene_moves").at(0);
      EXPECT_TRUE(move.at("moved").get<bool>()) << output;
      EXPECT_NEAR(move.at("rotation_rad").get<double>() * 180 / M_PI, 2.1, 0.6) << output;
    }
  }
  EXPECT_LT(rms[1], 1.2);
  EXPECT_LT(rms[0], 1.2);
}

}  // namespace
}  // namespace selfcal
