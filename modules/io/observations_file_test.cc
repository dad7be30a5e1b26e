// Observations, trajectory and JSON files, and atomic writes.
#include <sys/stat.h>

#include <algorithm>
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/io_test_util.h"
#include "io/observations_file.h"
#include "observations/joint_limits.h"
#include "io/report_json.h"
#include "io/trajectory_file.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (!SameBits(a.data()[i], b.data()[i])) return false;
  }
  return true;
}

ObservationSet RandomSet(std::mt19937_64* rng) {
  ObservationSet set;
  set.robot = selfcal::testing::Puma560();
  set.robot.links[2].beta = 1.0 / 3.0 * 1e-3;  // exercise betas and odd doubles
  set.camera.fx_px = 1000.0 + 1.0 / 7.0;
  set.camera.k1 = -0.0123456789012345;
  set.pixel_noise_px = 0.2;
  std::uniform_real_distribution<double> u(-0.5, 639.5), v(-0.5, 479.5), unit(0.0, 1.0);
  for (int p = 0; p < 12; ++p) {
    PoseObservation pose;
    pose.id = "p" + std::to_string(p);
    pose.role = p % 4 == 3 ? PoseRole::kVerification : PoseRole::kIdentification;
    pose.joints_rad.resize(6);
    for (int j = 0; j < 6; ++j) {
      const JointLimits& l = set.robot.limits[j];
      pose.joints_rad[j] = l.min_rad + (l.max_rad - l.min_rad) * unit(*rng);
    }
    for (int dot = 0; dot < 40; ++dot) {
      if (unit(*rng) < 0.8) pose.dots_px[dot * 3] = Eigen::Vector2d(u(*rng), v(*rng));
    }
    pose.dots_px[0] = Eigen::Vector2d(-0.5, 479.5);  // the image corners are inside
    pose.dots_px[3] = Eigen::Vector2d(639.5, -0.5);
    set.poses.push_back(pose);
  }
  set.yardsticks = {{0, 3, 0.25 + 1e-17}, {3, 6, 1.0 / 3.0}};
  set.check_distances = {{6, 9, 0.5123}};
  return set;
}

void ExpectBitIdentical(const ObservationSet& a, const ObservationSet& b) {
  EXPECT_EQ(a.robot.name, b.robot.name);
  ASSERT_EQ(a.robot.num_joints(), b.robot.num_joints());
  for (int i = 0; i < a.robot.num_joints(); ++i) {
    const LinkParameters &x = a.robot.links[i], &y = b.robot.links[i];
    EXPECT_TRUE(SameBits(x.alpha, y.alpha) && SameBits(x.a, y.a) && SameBits(x.beta, y.beta) &&
                SameBits(x.theta, y.theta) && SameBits(x.d, y.d)) << "joint " << i + 1;
    EXPECT_TRUE(SameBits(a.robot.limits[i].min_rad, b.robot.limits[i].min_rad));
    EXPECT_TRUE(SameBits(a.robot.limits[i].max_rad, b.robot.limits[i].max_rad));
  }
  for (const auto& [x, y] : {std::pair(&a.robot.base_from_link0, &b.robot.base_from_link0),
                             std::pair(&a.robot.link_n_from_flange, &b.robot.link_n_from_flange),
                             std::pair(&a.robot.flange_from_cam, &b.robot.flange_from_cam)}) {
    EXPECT_TRUE(SameBits(x->rotation, y->rotation));
    EXPECT_TRUE(SameBits(x->translation, y->translation));
  }
  EXPECT_EQ(a.camera.width_px, b.camera.width_px);
  EXPECT_EQ(a.camera.height_px, b.camera.height_px);
  for (const auto& [x, y] : {std::pair(a.camera.fx_px, b.camera.fx_px), std::pair(a.camera.mu, b.camera.mu),
                             std::pair(a.camera.cx_px, b.camera.cx_px), std::pair(a.camera.cy_px, b.camera.cy_px),
                             std::pair(a.camera.k1, b.camera.k1), std::pair(a.pixel_noise_px, b.pixel_noise_px)}) {
    EXPECT_TRUE(SameBits(x, y)) << x << " vs " << y;
  }
  for (const auto& [x, y] : {std::pair(&a.yardsticks, &b.yardsticks), std::pair(&a.check_distances, &b.check_distances)}) {
    ASSERT_EQ(x->size(), y->size());
    for (size_t i = 0; i < x->size(); ++i) {
      EXPECT_EQ((*x)[i].dot_a, (*y)[i].dot_a);
      EXPECT_EQ((*x)[i].dot_b, (*y)[i].dot_b);
      EXPECT_TRUE(SameBits((*x)[i].length_m, (*y)[i].length_m));
    }
  }
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (size_t p = 0; p < a.poses.size(); ++p) {
    EXPECT_EQ(a.poses[p].id, b.poses[p].id);
    EXPECT_EQ(a.poses[p].role, b.poses[p].role);
    EXPECT_EQ(a.poses[p].scene, b.poses[p].scene);
    EXPECT_TRUE(SameBits(a.poses[p].joints_rad, b.poses[p].joints_rad)) << a.poses[p].id;
    ASSERT_EQ(a.poses[p].dots_px.size(), b.poses[p].dots_px.size());
    for (const auto& [dot, px] : a.poses[p].dots_px) {
      ASSERT_EQ(b.poses[p].dots_px.count(dot), 1u);
      EXPECT_TRUE(SameBits(px, b.poses[p].dots_px.at(dot))) << a.poses[p].id << " dot " << dot;
    }
  }
}

TEST(ObservationsFile, SaveLoadRoundTripIsBitIdentical) {
  std::mt19937_64 rng(11);
  ObservationSet saved = RandomSet(&rng);
  saved.poses.front().scene = "board moved";  // a pose's scene survives the round trip; the others have none
  ASSERT_EQ(saved.Validate(), "");
  TempDir dir;
  const std::string path = dir.File("observations.yaml");
  ASSERT_TRUE(SaveObservations(saved, path).ok());
  Result<ObservationSet> loaded = LoadObservations(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ExpectBitIdentical(saved, *loaded);
  // Saving the loaded set reproduces the same bytes.
  ASSERT_TRUE(SaveObservations(*loaded, dir.File("again.yaml")).ok());
  EXPECT_EQ(ReadFile(path), ReadFile(dir.File("again.yaml")));
}

TEST(ObservationsFile, TheDocumentedExampleLoads) {
  const std::string doc_path = SourcePath("docs/observations-format.md");
  const std::string doc = ReadFile(doc_path);
  const size_t start = doc.find("```yaml\nformat: selfcal-observations");
  ASSERT_NE(start, std::string::npos);
  const size_t body = start + 8;
  const std::string example = doc.substr(body, doc.find("```", body) - body);
  // Named as the doc so that robot_file resolves relative to docs/.
  Result<yaml::YamlDocument> parsed = yaml::ParseYamlText(example, doc_path);
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  Result<ObservationSet> set = ParseObservations(*parsed);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->robot.name, "puma560");
  ASSERT_EQ(set->poses.size(), 2u);
  EXPECT_EQ(set->poses[1].role, PoseRole::kVerification);
  EXPECT_EQ(set->poses[0].joints_rad[1], DegToRad(30));
  EXPECT_EQ(set->poses[0].dots_px.at(2), Eigen::Vector2d(415.75, 300.0));
  EXPECT_EQ(set->yardsticks[0].length_m, 0.25);
  EXPECT_EQ(set->check_distances[0].length_m, 0.3125);
  EXPECT_EQ(set->camera.fx_px, 1000.0);
}

// The documented example with one edit, written next to the shipped robot configs' relative path.
class ObservationsEdits : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string doc = ReadFile(SourcePath("docs/observations-format.md"));
    const size_t body = doc.find("```yaml\nformat: selfcal-observations") + 8;
    example_ = doc.substr(body, doc.find("```", body) - body);
    const size_t at = example_.find("../config/robots/puma560.yaml");
    example_.replace(at, 29, SourcePath("config/robots/puma560.yaml"));
    path_ = dir_.File("edited.yaml");
  }
  Status Load(const std::string& from, const std::string& to) {
    std::string text = example_;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    WriteFile(path_, text);
    return LoadObservations(path_).status();
  }
  ::testing::AssertionResult Refused(const Status& status, const std::string& why) {
    if (status.ok()) return ::testing::AssertionFailure() << "accepted";
    if (status.code() != ErrorCode::kInvalidInput || status.message().find(why) == std::string::npos ||
        status.message().find(path_) == std::string::npos) {
      return ::testing::AssertionFailure() << "expected \"" << why << "\" in: " << status.ToString();
    }
    return ::testing::AssertionSuccess();
  }
  TempDir dir_;
  std::string example_, path_;
};

TEST_F(ObservationsEdits, BaselineLoads) { EXPECT_TRUE(Load("version: 1", "version: 1").ok()); }

TEST_F(ObservationsEdits, UnknownMajorVersionIsRefused) {
  const Status status = Load("version: 1", "version: 2");
  EXPECT_TRUE(Refused(status, "`version` = `2` at " + path_ + ":2: this selfcal reads selfcal-observations version 1.x only"));
  EXPECT_EQ(status.message().find("unknown key"), std::string::npos) << "only the version is reported";
  EXPECT_TRUE(Load("version: 1", "version: 1.7").ok());
  EXPECT_TRUE(Refused(Load("format: selfcal-observations", "format: selfcal-trajectory"), "expected `selfcal-observations`"));
}

TEST_F(ObservationsEdits, C1MisspeltKey) {
  EXPECT_TRUE(Refused(Load("pixel_noise_px", "pixel_nosie_px"),
                      "unknown key `pixel_nosie_px` at " + path_ + ":5; did you mean `pixel_noise_px`?"));
}

TEST_F(ObservationsEdits, C2AllMissingKeysTogether) {
  const Status status = Load("camera: {width_px: 640, height_px: 480, fx_px: 1000.0, mu: 1.0, cx_px: 319.5, cy_px: 239.5, k1: 0.0}\npixel_noise_px: 0.2\n", "");
  EXPECT_TRUE(Refused(status, "missing required keys `camera`, `pixel_noise_px` in the document"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0, mu: 1.0, cx_px: 319.5,", "mu: 1.0,"),
                      "missing required keys `fx_px`, `cx_px` in `camera`"));
}

TEST_F(ObservationsEdits, C3CameraValues) {
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: .nan"), "`camera.fx_px` = `.nan` at " + path_ + ":4 is not finite"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: .inf"), "is not finite"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: 0"), "`camera.fx_px` = `0` at " + path_ + ":4 is out of range: must be in (0, 1e+06]"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: -1000"), "is out of range"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: \"1000\""), "is not a number (found a quoted string)"));
  EXPECT_TRUE(Refused(Load("fx_px: 1000.0", "fx_px: one thousand"), "`camera.fx_px` = `one thousand` at " + path_ + ":4 is not a number"));
  EXPECT_TRUE(Refused(Load("width_px: 640", "width_px: 640.5"), "`camera.width_px` = `640.5`"));
  EXPECT_TRUE(Refused(Load("cx_px: 319.5", "cx_px: 900"), "cx_px = 900 must lie in [0, width]"));
  EXPECT_TRUE(Refused(Load("pixel_noise_px: 0.2", "pixel_noise_px: -0.2"), "`pixel_noise_px` = `-0.2`"));
  // Issue 16: a noise far below any camera's (the weighted normal equations overflow) is named by key and line.
  EXPECT_TRUE(Refused(Load("pixel_noise_px: 0.2", "pixel_noise_px: 1e-150"),
                      "`pixel_noise_px` = `1e-150` at " + path_ + ":5 is out of range: must be in [1e-06, 100]"));
  EXPECT_TRUE(Load("pixel_noise_px: 0.2", "pixel_noise_px: 1e-6").ok());
  EXPECT_TRUE(Refused(Load("length_mm: 250.0", "length_mm: 0"), "`yardsticks[0].length_mm` = `0`"));
}

// Issue 36: a known distance of 1e-300 m (the mutation campaign's) was taken: positive, but no two dots' centres
// are that close, and no scale comes from it. A length is at least 1 mm, at most 100 m, named by key and line.
TEST_F(ObservationsEdits, AKnownDistanceShorterThanAMillimetreIsRefusedByLine) {
  const std::string line = std::to_string(1 + std::count(example_.begin(), example_.begin() + static_cast<std::ptrdiff_t>(
                                                                                example_.find("length_mm: 250.0")), '\n'));
  EXPECT_TRUE(Refused(Load("length_mm: 250.0", "length_mm: 1e-300"),
                      "`yardsticks[0].length_mm` = `1e-300` at " + path_ + ":" + line +
                          " is out of range: must be in [1, 100000]"));
  EXPECT_TRUE(Refused(Load("length_mm: 250.0", "length_mm: 0.999"), "`yardsticks[0].length_mm` = `0.999`"));
  EXPECT_TRUE(Refused(Load("length_mm: 250.0", "length_m: 1e-300"), "`yardsticks[0].length_m` = `1e-300`"));
  EXPECT_TRUE(Refused(Load("length_mm: 250.0", "length_mm: 100001"), "`yardsticks[0].length_mm` = `100001`"));
  EXPECT_TRUE(Load("length_mm: 250.0", "length_mm: 1").ok());
  EXPECT_TRUE(Load("length_mm: 250.0", "length_m: 100").ok());
}

TEST_F(ObservationsEdits, C3JointsOutsidePlausibleRanges) {
  EXPECT_TRUE(Refused(Load("[0, 30, -150, 0, 45, 0]", "[0, 30, 12000, 0, 45, 0]"),
                      "`poses[0].joints_deg[2]` = `12000` at " + path_ + ":13 is out of range: must be in [-720, 720]"));
  // Joint 2 of the PUMA stops at 225 deg, but a recorded 230 is what the controller read: kept as recorded,
  // and named by observations/joint_limits.h (calibrate's warning).
  ASSERT_TRUE(Load("[0, 30, -150, 0, 45, 0]", "[0, 230, -150, 0, 45, 0]").ok());
  Result<ObservationSet> outside = LoadObservations(path_);
  ASSERT_TRUE(outside.ok());
  EXPECT_NEAR(outside->poses[0].joints_rad[1], DegToRad(230), 1e-12);
  const std::vector<std::string> named = PosesOutsideJointLimits(*outside);
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0], "pose " + outside->poses[0].id + " (index 0): joint 2 = 230 deg outside [-45, 225] deg of robot `puma560`");
  // ... and written back as read.
  EXPECT_TRUE(SaveObservations(*outside, dir_.File("again.yaml")).ok());
  EXPECT_TRUE(Refused(Load("[0, 30, -150, 0, 45, 0]", "[0, 30, -150, 0, 45]"),
                      "`poses[0].joints_deg` at " + path_ + ":13 has 5 values, expected 6"));
  EXPECT_TRUE(Refused(Load("joints_deg: [0, 30, -150, 0, 45, 0]", "joints_deg: [0, 30, -150, 0, 45, 0]\n    joints_rad: [0, 0, 0, 0, 0, 0]"),
                      "give the same quantity twice"));
  EXPECT_TRUE(Refused(Load("joints_deg: [0, 30, -150, 0, 45, 0]", "joints: [0, 30, -150, 0, 45, 0]"),
                      "`poses[0].joints` at " + path_ + ":13 is not allowed here: the unit goes in the key: `joints_deg` or `joints_rad`"));
}

// Issue 36: a verification pose with radians under `joints_deg` was taken as degrees (every joint within a
// degree of its zero) and silently contributed nothing; now the reader refuses it naming the pose's line.
TEST_F(ObservationsEdits, C4RadiansUnderADegreeKeyAreRefusedNamingTheLine) {
  const std::string radians = "joints_deg: [0.17453, 0.61087, -2.70526, 0.08727, 0.69813, -0.17453]";
  EXPECT_TRUE(Refused(Load("joints_deg: [10, 35, -155, 5, 40, -10]", radians),
                      "`poses[1].joints_deg` at " + path_ + ":17 holds [0.17453, 0.61087, -2.70526, 0.08727, 0.69813, "
                      "-0.17453]: every value within +-6.2832 (2 pi), as joint angles in radians are"));
  EXPECT_TRUE(Refused(Load("joints_deg: [10, 35, -155, 5, 40, -10]", "joints_deg: [0, 0, 0, 0, 0, 3]"),
                      "give radians under `joints_rad`"));
  // The zero pose reads the same in both units; radians under their own key; degrees beyond 2 pi.
  EXPECT_TRUE(Load("joints_deg: [10, 35, -155, 5, 40, -10]", "joints_deg: [0, 0, 0, 0, 0, 0]").ok());
  EXPECT_TRUE(Load("joints_deg: [10, 35, -155, 5, 40, -10]", "joints_rad: [0, 0, 0, 0, 0, 0.05]").ok());
  EXPECT_TRUE(Load("joints_deg: [10, 35, -155, 5, 40, -10]", "joints_deg: [0, 0, 0, 0, 0, 6.3]").ok());
  // The reproducer kept for the fuzz harness: refused at its line.
  const std::string kept = SourcePath("fuzz/regressions/observations/verification-pose-radians-under-joints-deg.yaml");
  const Status status = LoadObservations(kept).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("`poses[1].joints_deg` at " + kept + ":17 holds [0.17453,"), std::string::npos)
      << status.ToString();
}

TEST_F(ObservationsEdits, C3DotsOutsideTheImageOrRepeated) {
  EXPECT_TRUE(Refused(Load("[1, 100.0, 20.0]", "[1, 100.0, 480.0]"), "dot 1 at (100, 480) px in `poses[0].dots[1]` at " + path_ +
                                                                     ":14 lies outside the 640x480 image"));
  EXPECT_TRUE(Refused(Load("[1, 100.0, 20.0]", "[0, 100.0, 20.0]"), "dot 0 appears twice in `poses[0].dots`"));
  EXPECT_TRUE(Refused(Load("[1, 100.0, 20.0]", "[-1, 100.0, 20.0]"), "`poses[0].dots[1][0]` = `-1`"));
  EXPECT_TRUE(Refused(Load("[1, 100.0, 20.0]", "[1, 100.0]"), "must be [dot id, u_px, v_px]"));
}

// The set's own checks name the file and the line of the pose or distance they refuse.
TEST_F(ObservationsEdits, SetLevelValidationNamesTheFileAndLine) {
  auto line_of = [this](const std::string& text) {
    const size_t at = example_.find(text);
    EXPECT_NE(at, std::string::npos) << text;
    return std::to_string(1 + std::count(example_.begin(), example_.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  };
  const std::string yardstick = line_of("{dot_a: 0, dot_b: 2, length_mm: 250.0}");
  EXPECT_TRUE(Refused(Load("{dot_a: 0, dot_b: 2, length_mm: 250.0}", "{dot_a: 0, dot_b: 99, length_mm: 250.0}"),
                      path_ + ":" + yardstick + ": yardstick 0-99: dot 99 is never observed"));
  EXPECT_TRUE(Refused(Load("{dot_a: 0, dot_b: 2, length_mm: 250.0}", "{dot_a: 2, dot_b: 2, length_mm: 250.0}"),
                      path_ + ":" + yardstick + ": yardstick 2-2: both ends are the same dot"));
  EXPECT_TRUE(Refused(Load("id: v00", "id: p00"), path_ + ":" + line_of("id: v00") + ": pose p00: duplicate pose id"));
  // A scene that only the verification pose sees: no point of it can be placed, refused at that pose's line.
  EXPECT_TRUE(Refused(Load("    role: verification\n", "    role: verification\n    scene: next_day\n"),
                      path_ + ":" + line_of("id: v00") + ": pose v00: its scene `next_day` is a scene that no "
                                                          "identification pose sees"));
}

TEST_F(ObservationsEdits, RobotAndRobotFile) {
  EXPECT_TRUE(Refused(Load("robot_file: ", "robot_file: missing.yaml\nrobot_file_x: "), "unknown key `robot_file_x`"));
  EXPECT_TRUE(Refused(Load("robot_file: " + SourcePath("config/robots/puma560.yaml"), "robot_file: nowhere.yaml"),
                      "`robot_file` at " + path_ + ":3: cannot open " + dir_.path() + "/nowhere.yaml"));
  EXPECT_TRUE(Refused(Load("robot_file: " + SourcePath("config/robots/puma560.yaml"), "# no robot"),
                      "missing required key `robot` (or `robot_file`)"));
}

TEST(ObservationsFile, C8MutatedFilesAreRefusedCleanlyOrLoad) {
  std::mt19937_64 rng(12);
  TempDir dir;
  const std::string good = dir.File("good.yaml");
  ASSERT_TRUE(SaveObservations(RandomSet(&rng), good).ok());
  const std::string text = ReadFile(good);
  const std::string path = dir.File("mutated.yaml");
  for (int trial = 0; trial < 400; ++trial) {
    std::string mutated = text;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = rng() % mutated.size();
      switch (rng() % 4) {
        case 0: mutated[at] = static_cast<char>(rng()); break;
        case 1: mutated.erase(at, 1 + rng() % 40); break;
        case 2: mutated.insert(at, std::string(1, "[]{}:-,#&*!'\"\n 9."[rng() % 18])); break;
        case 3: mutated.resize(at); break;
      }
      if (mutated.empty()) break;
    }
    WriteFile(path, mutated);
    Result<ObservationSet> loaded = LoadObservations(path);
    if (!loaded.ok()) {
      EXPECT_EQ(loaded.status().code(), ErrorCode::kInvalidInput);
      EXPECT_NE(loaded.status().message().find(path), std::string::npos) << loaded.status().message();
    }
  }
}

TEST(TrajectoryFile, SaveLoadRoundTripIsExact) {
  const RobotModel robot = selfcal::testing::Puma560();
  std::vector<Eigen::VectorXd> poses;
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int p = 0; p < 25; ++p) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) q[j] = robot.limits[j].min_rad + (robot.limits[j].max_rad - robot.limits[j].min_rad) * unit(rng);
    poses.push_back(q);
  }
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  ASSERT_TRUE(SaveTrajectory(poses, path, "puma560", "25 random poses").ok());
  Result<std::vector<Eigen::VectorXd>> loaded = LoadTrajectory(path, robot);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->size(), poses.size());
  for (size_t p = 0; p < poses.size(); ++p) EXPECT_TRUE(SameBits((*loaded)[p], poses[p])) << p;
}

// The planned_for block (camera, scene, constraints) comes back bit for bit; a bad value names its key.
TEST(TrajectoryFile, PlannedForRoundTripsAndIsChecked) {
  TrajectoryFile file;
  file.robot = "puma560";
  file.poses = {Eigen::VectorXd::Constant(6, 0.25), Eigen::VectorXd::Constant(6, -0.125)};
  planning::PlannedFor p;
  p.camera.width_px = 640;
  p.camera.height_px = 480;
  p.camera.fx_px = 1000.125;
  p.camera.cx_px = 319.5;
  p.camera.cy_px = 239.5;
  p.camera.k1 = -0.01;
  p.constraints.max_image_motion_px = 77.5;
  p.constraints.min_axis_sine = 0.08;
  for (int k = 0; k < 8; ++k) p.scene.dots_in_base.emplace_back(0.8 + 0.01 * k, -0.1 * k, -0.3);
  p.scene.extent_in_base = p.scene.dots_in_base;
  file.planned_for = p;
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  ASSERT_TRUE(SaveTrajectoryFile(file, path).ok());
  Result<TrajectoryFile> loaded = LoadTrajectoryFile(path, 6);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_TRUE(loaded->planned_for.has_value());
  const planning::PlannedFor& q = *loaded->planned_for;
  EXPECT_EQ(q.camera.fx_px, p.camera.fx_px);
  EXPECT_EQ(q.camera.k1, p.camera.k1);
  EXPECT_EQ(q.constraints.max_image_motion_px, 77.5);
  EXPECT_EQ(q.constraints.min_axis_sine, 0.08);
  EXPECT_EQ(q.constraints.joint_margin_rad, p.constraints.joint_margin_rad);
  ASSERT_EQ(q.scene.dots_in_base.size(), 8u);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR((q.scene.dots_in_base[k] - p.scene.dots_in_base[k]).norm(), 0, 1e-15) << k;
  std::string text = ReadFile(path);
  const size_t at = text.find("max_image_motion_px: ");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, text.find('\n', at) - at, "max_image_motion_px: -3");
  WriteFile(path, text);
  Result<TrajectoryFile> bad = LoadTrajectoryFile(path, 6);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("planned_for.max_image_motion_px"), std::string::npos) << bad.status().message();
}

TEST(TrajectoryFile, C5WrongJointCountNamesEveryBadPose) {
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  WriteFile(path, "format: selfcal-trajectory\nversion: 1\nrobot: puma560\ndescription: \"test\"\nposes_deg:\n"
                  "  - [0, 30, -150, 0, 45, 0]\n  - [0, 30, -150, 0, 45, 0]\n  - [0, 30, -150, 0, 45]\n"
                  "  - [0, 30, -150, 0, 45, 0]\n  - [0, 30, -150, 0, 45, 0, 7]\n");
  const Status status = LoadTrajectory(path, 6).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("pose 2 (`poses_deg[2]` at " + path + ":8) has 5 joint values, the robot has 6"),
            std::string::npos) << status.message();
  EXPECT_NE(status.message().find("pose 4 (`poses_deg[4]` at " + path + ":10) has 7 joint values"), std::string::npos);
  Result<std::vector<Eigen::VectorXd>> ok = LoadTrajectory(path, 5);
  EXPECT_FALSE(ok.ok());
  WriteFile(path, "format: selfcal-trajectory\nversion: 1\nposes:\n  - [0, 30, -150, 0, 45, 0]\n");
  EXPECT_NE(LoadTrajectory(path, 6).status().message().find("`poses` at " + path + ":3 is not allowed here: the unit goes in the key"),
            std::string::npos) << LoadTrajectory(path, 6).status().message();
}

// The mutation campaign's plan of 42,000 poses (one row repeated to 8 MiB) made `plan --check` grow to 22 GB:
// a plan over the limit is refused naming the file, the line, the count and the limit.
TEST(TrajectoryFile, MorePosesThanTheLimitAreRefused) {
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  std::string text = "format: selfcal-trajectory\nversion: 1\nposes_deg:\n";
  for (int i = 0; i <= kMaxTrajectoryPoses; ++i) text += "  - [0, 30, -150, 0, 45, 0]\n";
  WriteFile(path, text);
  const Status status = LoadTrajectoryFile(path, 6).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("`poses_deg` at " + path + ":4 holds 5001 poses, more than the limit of 5000"),
            std::string::npos) << status.message();
}

// An empty `robot:` (the mutation campaign's `robot: ""`) was accepted as no robot at all.
TEST(TrajectoryFile, AnEmptyRobotNameIsRefused) {
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  WriteFile(path, "format: selfcal-trajectory\nversion: 1\nrobot: \"\"\nposes_deg:\n  - [0, 30, -150, 0, 45, 0]\n");
  const Status status = LoadTrajectoryFile(path, 6).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("`robot` at " + path + ":3 is empty"), std::string::npos) << status.message();
}

// Issue 16: an empty plan crashed run (with and without --dry-run) and simulate --trajectory at its first
// pose; it is a config error naming the file and the line.
TEST(TrajectoryFile, C7AnEmptyPoseListIsRefusedNamingFileAndLine) {
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  for (const char* key : {"poses_rad", "poses_deg"}) {
    WriteFile(path, std::string("format: selfcal-trajectory\nversion: 1\n") + key + ": []\n");
    const Status status = LoadTrajectory(path, 6).status();
    EXPECT_EQ(status.code(), ErrorCode::kInvalidInput) << key;
    EXPECT_NE(status.message().find(std::string("`") + key + "` at " + path + ":3 is empty: a plan needs at least one pose"),
              std::string::npos)
        << status.message();
  }
}

// Issue 36: a plan whose `poses_rad` was renamed `poses_deg` passed `plan --check` (every joint within a
// few degrees of zero, inside every limit); the file's values, all within 2 pi, are refused as radians.
TEST(TrajectoryFile, C4RadiansUnderPosesDegAreRefusedNamingTheLine) {
  const std::string kept = SourcePath("fuzz/regressions/trajectory/plan-poses-rad-renamed-poses-deg.yaml");
  const Status status = LoadTrajectory(kept, 6).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find("`poses_deg[0]` at " + kept + ":104 holds ["), std::string::npos) << status.ToString();
  EXPECT_NE(status.message().find("give radians under `poses_rad`"), std::string::npos) << status.ToString();
  EXPECT_NE(status.message().find("so do all 25 rows of `poses_deg` at " + kept + ":103"), std::string::npos)
      << status.ToString();
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  const std::string head = "format: selfcal-trajectory\nversion: 1\n";
  WriteFile(path, head + "poses_deg:\n  - [0, 0, 0, 0, 0, 0]\n  - [0, 0.5, -1.2, 0, 0.7, 0]\n");
  EXPECT_NE(LoadTrajectory(path, 6).status().message().find("`poses_deg[0]` at " + path + ":4 holds [0, 0, 0, 0, 0, 0]"),
            std::string::npos);
  // One row beyond 2 pi: degrees. All zero: the same in both units. The radians under their key.
  WriteFile(path, head + "poses_deg:\n  - [0, 0, 0, 0, 0, 0]\n  - [0, 30, -150, 0, 45, 0]\n");
  EXPECT_TRUE(LoadTrajectory(path, 6).ok());
  WriteFile(path, head + "poses_deg:\n  - [0, 0, 0, 0, 0, 0]\n");
  EXPECT_TRUE(LoadTrajectory(path, 6).ok());
  WriteFile(path, head + "poses_rad:\n  - [0, 0.5, -1.2, 0, 0.7, 0]\n");
  EXPECT_TRUE(LoadTrajectory(path, 6).ok());
}

TEST(TrajectoryFile, C6PosesOutsideTheLimitsAreRefused) {
  TempDir dir;
  const std::string path = dir.File("plan.yaml");
  WriteFile(path, "format: selfcal-trajectory\nversion: 1\nposes_deg:\n  - [0, 30, -150, 0, 45, 0]\n  - [0, 230, -150, 0, 45, 0]\n");
  EXPECT_TRUE(LoadTrajectory(path, 6).ok());
  const Status status = LoadTrajectory(path, selfcal::testing::Puma560()).status();
  EXPECT_NE(status.message().find("pose 1 (`poses_deg[1]` at " + path + ":5): joint 2 = 230 deg is outside its limits [-45, 225] deg"),
            std::string::npos) << status.message();
  WriteFile(path, "format: selfcal-trajectory\nversion: 1\nrobot: ur5e\nposes_deg: []\n");
  EXPECT_NE(LoadTrajectory(path, selfcal::testing::Puma560()).status().message().find("the robot model is `puma560`"),
            std::string::npos);
}

TEST(AtomicFile, ReplacesTheTargetAndLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.File("result.yaml");
  WriteFile(path, "old contents\n");
  ASSERT_TRUE(WriteFileAtomically(path, "new contents\n").ok());
  EXPECT_EQ(ReadFile(path), "new contents\n");
  EXPECT_EQ(dir.List(), std::vector<std::string>{"result.yaml"});
}

TEST(AtomicFile, FailureLeavesTheTargetUntouchedAndNoTemporaryFile) {
  TempDir dir;
  const Status missing_dir = WriteFileAtomically(dir.File("no/such/dir/result.yaml"), "x");
  EXPECT_EQ(missing_dir.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(missing_dir.message().find(dir.File("no/such/dir/result.yaml")), std::string::npos);
  // The target is a non-empty directory: rename fails after the temporary file was written.
  ASSERT_EQ(::mkdir(dir.File("taken").c_str(), 0755), 0);
  WriteFile(dir.File("taken/inner"), "keep");
  const Status taken = WriteFileAtomically(dir.File("taken"), "x");
  EXPECT_EQ(taken.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(taken.message().find("rename failed"), std::string::npos) << taken.message();
  EXPECT_EQ(dir.List(), std::vector<std::string>{"taken"});
  EXPECT_EQ(ReadFile(dir.File("taken/inner")), "keep");
}

TEST(JsonFile, WriteReadRoundTripAndGuards) {
  TempDir dir;
  const std::string path = dir.File("report.json");
  nlohmann::json doc = {{"format", "selfcal-report"}, {"version", 1}, {"rms_px", 0.1 + 0.2}, {"sigma", std::nan("")}};
  ASSERT_TRUE(WriteJsonFile(doc, path).ok());
  Result<nlohmann::json> read = ReadJsonFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ((*read)["rms_px"].get<double>(), 0.1 + 0.2);
  EXPECT_TRUE((*read)["sigma"].is_null());
  EXPECT_EQ(dir.List(), std::vector<std::string>{"report.json"});
  EXPECT_EQ(WriteJsonFile(nlohmann::json{{"bad", "\xC3\x28"}}, dir.File("bad.json")).code(), ErrorCode::kInvalidInput);
  // The mutation campaign's refusals of nesting ("at byte N") and of number overflow (nlohmann's text) named
  // no line.
  WriteFile(path, "{\n  \"a\":\n" + std::string(10000, '[') + std::string(10000, ']') + "\n}\n");
  EXPECT_NE(ReadJsonFile(path).status().message().find(path + ":3: JSON nested deeper than 64"), std::string::npos)
      << ReadJsonFile(path).status().message();
  WriteFile(path, "{\n  \"a\": 1,\n  \"b\": 1e400\n}\n");
  EXPECT_EQ(ReadJsonFile(path).status().message(), path + ":3: the number 1e400 is beyond the range of a double");
  WriteFile(path, "{\"a\":\n [1, 2,");
  EXPECT_NE(ReadJsonFile(path).status().message().find(path + ":2: malformed JSON: "), std::string::npos)
      << ReadJsonFile(path).status().message();
  // Issue 36: a key given twice, the last value winning, is refused naming the line.
  WriteFile(path, "{\n  \"format\": \"selfcal-report\",\n  \"format\": \"x\"\n}\n");
  EXPECT_EQ(ReadJsonFile(path).status().message(),
            path + ":3: `format` is given twice (lines 2 and 3): a JSON reader would keep one of them without a word; "
                   "keep one");
}

}  // namespace
}  // namespace selfcal::io
