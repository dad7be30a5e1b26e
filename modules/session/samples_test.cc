#include "session/samples.h"

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "base/crc32.h"
#include "session/session_test_util.h"
#include "support/test_robots.h"

namespace selfcal::session {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::CreateTestSession;
using testing::TempDir;
using testing::WriteFile;

const std::vector<double> kJoints = {0.1, -0.2, 0.3, 0.0, 0.5, -0.6};

json Started(int num_poses) {
  return {{"type", "session_started"}, {"time_s", 0.0}, {"num_poses", num_poses}, {"mode", "simulated"}};
}
json Planned(int pose, const std::string& role = "identification") {
  return {{"type", "pose_planned"},
          {"pose", pose},
          {"id", "p0" + std::to_string(pose)},
          {"role", role},
          {"joints_rad", kJoints}};
}
std::string ImageOf(int pose, int attempt) {
  return "images/p0" + std::to_string(pose) + (attempt ? "_" + std::to_string(attempt) : "") + ".png";
}
json Frame(int pose, int attempt = 0, const std::string& crc = "0000abcd", int bytes = 1000) {
  return {{"type", "frame_written"},
          {"pose", pose},
          {"image", ImageOf(pose, attempt)},
          {"crc32", crc},
          {"bytes", bytes},
          {"exposure_time_s", 1.5},
          {"sequence", 10 + pose}};
}
json Accepted(int pose, int attempt = 0, const std::string& role = "identification") {
  return {{"type", "sample_accepted"},
          {"pose", pose},
          {"id", "p0" + std::to_string(pose)},
          {"role", role},
          {"joints_rad", kJoints},
          {"joint_time_s", 1.2},
          {"settle_time_s", 1.3},
          {"exposure_time_s", 1.5},
          {"image", ImageOf(pose, attempt)},
          {"dots",
           {{{"id", 0}, {"u", 100.5}, {"v", 200.25}, {"area", 80.0}, {"w", 10.0}, {"h", 9.0}},
            {{"id", 3}, {"u", 300.0}, {"v", 50.0}, {"area", 60.0}, {"w", 9.0}, {"h", 8.0}}}}};
}
json Skipped(int pose, const std::string& reason) {
  return {{"type", "sample_skipped"}, {"pose", pose}, {"reason", reason}, {"detail", "why"}};
}

// Pose 0 accepted; pose 1 move failed (final skip) with a fault; pose 2 interrupted by a halt, resumed,
// accepted, then accepted again; pose 3 not visited; and a record of a future type.
std::vector<json> SyntheticJournal() {
  std::vector<json> records = {Started(4), Planned(0), Planned(1), Planned(2, "verification"), Planned(3)};
  const std::vector<json> events = {
      {{"type", "move_started"}, {"pose", 0}, {"time_s", 0.1}, {"from_rad", kJoints}},
      {{"type", "move_done"}, {"pose", 0}, {"time_s", 1.0}},
      {{"type", "settled"}, {"pose", 0}, {"time_s", 1.3}},
      Frame(0),
      Accepted(0),
      {{"type", "move_started"}, {"pose", 1}, {"time_s", 2.0}, {"from_rad", kJoints}},
      {{"type", "fault"}, {"kind", "move_rejected"}, {"pose", 1}, {"detail", "limit"}},
      Skipped(1, "move_failed"),
      Frame(2),
      Skipped(2, "interrupted"),
      {{"type", "halted"}, {"reason", "operator_stop"}, {"pose", 2}, {"detail", "button"}},
      {{"type", "resumed"}, {"time_s", 10.0}},
      {{"type", "tracker_state"}, {"anything", true}},  // unknown type: tolerated
      Frame(2, 1),
      Accepted(2, 1, "verification"),
      Accepted(2, 1, "verification"),  // a duplicate: the first counts
  };
  records.insert(records.end(), events.begin(), events.end());
  return records;
}

TEST(SamplesTest, ReadsASyntheticJournal) {
  const std::vector<json> records = SyntheticJournal();
  Result<SessionLog> read = ReadSessionLog(records);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  const SessionLog& log = *read;
  EXPECT_TRUE(log.started);
  EXPECT_EQ(log.num_poses, 4);
  EXPECT_EQ(log.mode, "simulated");
  EXPECT_TRUE(log.plan_complete());
  ASSERT_EQ(log.plan.size(), 4u);
  EXPECT_EQ(log.plan[2].id, "p02");
  EXPECT_EQ(log.plan[2].role, PoseRole::kVerification);
  EXPECT_EQ(std::vector<double>(log.plan[3].joints_rad.data(), log.plan[3].joints_rad.data() + log.plan[3].joints_rad.size()),
            kJoints);

  ASSERT_TRUE(log.accepted[0].has_value());
  EXPECT_FALSE(log.accepted[1].has_value());
  ASSERT_TRUE(log.accepted[2].has_value());
  EXPECT_FALSE(log.accepted[3].has_value());
  EXPECT_EQ(log.NumAccepted(), 2);
  const AcceptedSample& first = *log.accepted[0];
  EXPECT_EQ(first.id, "p00");
  EXPECT_EQ(first.image, "images/p00.png");
  EXPECT_EQ(first.joint_time_s, 1.2);
  EXPECT_EQ(first.settle_time_s, 1.3);
  ASSERT_EQ(first.dots.size(), 2u);
  EXPECT_EQ(first.dots[1].id, 3);
  EXPECT_EQ(first.dots[0].u_px, 100.5);
  EXPECT_EQ(first.dots[0].v_px, 200.25);
  EXPECT_EQ(first.dots[0].height_px, 9.0);
  EXPECT_FALSE(first.sim_clock_s.has_value());
  EXPECT_EQ(first.record, 9u);
  EXPECT_EQ(log.accepted[2]->image, "images/p02_1.png");
  EXPECT_EQ(log.accepted[2]->record, 19u);
  EXPECT_EQ(log.duplicate_accepts, std::vector<std::size_t>{20});

  ASSERT_EQ(log.skips[1].size(), 1u);
  EXPECT_EQ(log.skips[1][0].reason, "move_failed");
  EXPECT_EQ(log.skips[2][0].reason, "interrupted");
  EXPECT_EQ(log.skips_by_reason, (std::map<std::string, int>{{"interrupted", 1}, {"move_failed", 1}}));
  EXPECT_EQ(log.faults_by_kind, (std::map<std::string, int>{{"move_rejected", 1}}));
  EXPECT_EQ(log.halts_by_reason, (std::map<std::string, int>{{"operator_stop", 1}}));
  EXPECT_EQ(log.resumes, 1);
  EXPECT_FALSE(log.finished);
  EXPECT_EQ(log.unknown_records, 1u);
  EXPECT_EQ(log.frames.size(), 3u);
  EXPECT_EQ(log.frames.at("images/p02_1.png").crc32, 0xabcdu);

  EXPECT_TRUE(log.PoseDone(0));
  EXPECT_TRUE(log.PoseDone(1));  // move_failed is final
  EXPECT_TRUE(log.PoseDone(2));
  EXPECT_FALSE(log.PoseDone(3));
  EXPECT_EQ(log.FirstPoseWithoutAcceptedSample(), 3);
  ASSERT_NE(log.LastAcceptedSample(), nullptr);
  EXPECT_EQ(log.LastAcceptedSample()->pose, 2);
}

TEST(SamplesTest, ResumePoint) {
  std::vector<json> records = {Started(3), Planned(0), Planned(1), Planned(2)};
  EXPECT_EQ(ReadSessionLog(records)->FirstPoseWithoutAcceptedSample(), 0);
  EXPECT_EQ(ReadSessionLog(records)->LastAcceptedSample(), nullptr);
  records.push_back(Skipped(0, "interrupted"));  // not final: pose 0 is visited again
  EXPECT_EQ(ReadSessionLog(records)->FirstPoseWithoutAcceptedSample(), 0);
  records.push_back(Skipped(0, "too_few_dots"));
  EXPECT_EQ(ReadSessionLog(records)->FirstPoseWithoutAcceptedSample(), 1);
  records.push_back(Frame(1));
  EXPECT_EQ(ReadSessionLog(records)->FirstPoseWithoutAcceptedSample(), 1);  // a frame alone does not count
  records.push_back(Accepted(1));
  records.push_back(Frame(2));
  records.push_back(Accepted(2));
  records.push_back({{"type", "finished"}, {"time_s", 20.0}});
  Result<SessionLog> done = ReadSessionLog(records);
  ASSERT_TRUE(done.ok()) << done.status().ToString();
  EXPECT_EQ(done->FirstPoseWithoutAcceptedSample(), 3);
  EXPECT_TRUE(done->finished);
  EXPECT_EQ(done->LastAcceptedSample()->pose, 2);

  // A plan cut short by a crash: the poses not planned yet are not done.
  Result<SessionLog> partial = ReadSessionLog({Started(3), Planned(0), Skipped(0, "bad_frame")});
  ASSERT_TRUE(partial.ok());
  EXPECT_FALSE(partial->plan_complete());
  EXPECT_EQ(partial->FirstPoseWithoutAcceptedSample(), 1);
  // An empty journal (a crash right after creation).
  Result<SessionLog> empty = ReadSessionLog({});
  ASSERT_TRUE(empty.ok());
  EXPECT_FALSE(empty->started);
  EXPECT_EQ(empty->FirstPoseWithoutAcceptedSample(), 0);
}

TEST(SamplesTest, FinalSkipReasons) {
  for (const char* reason : {"move_failed", "not_settled", "bad_reading", "no_frame", "bad_frame", "too_few_dots",
                             "moved_after_settle"}) {
    EXPECT_TRUE(IsFinalSkipReason(reason)) << reason;
  }
  EXPECT_FALSE(IsFinalSkipReason("interrupted"));
  EXPECT_FALSE(IsFinalSkipReason("no_space"));
  EXPECT_STREQ(PoseRoleName(PoseRole::kVerification), "verification");
}

// --revisit-skipped N: a pose skipped for a revisitable reason k times is done once k > N; other final
// reasons close it whatever the bound.
TEST(SamplesTest, RevisitBoundCountsTheSkipsOfAPose) {
  std::vector<json> records = {Started(3), Planned(0), Planned(1), Planned(2), Skipped(0, "moved_after_settle"),
                               Skipped(1, "move_failed")};
  Result<SessionLog> once = ReadSessionLog(records);
  ASSERT_TRUE(once.ok()) << once.status().ToString();
  EXPECT_TRUE(once->PoseDone(0, 0));
  EXPECT_FALSE(once->PoseDone(0, 1));
  EXPECT_TRUE(once->PoseDone(1, 5));  // move_failed is not retried
  EXPECT_EQ(once->PosesToVisit(1), (std::vector<int>{0, 2}));
  records.push_back(Skipped(0, "too_few_dots"));
  Result<SessionLog> twice = ReadSessionLog(records);
  ASSERT_TRUE(twice.ok());
  EXPECT_TRUE(twice->PoseDone(0, 1));
  EXPECT_FALSE(twice->PoseDone(0, 2));
  EXPECT_EQ(twice->PosesToVisit(1), (std::vector<int>{2}));
  EXPECT_TRUE(IsRevisitableSkipReason("moved_after_settle"));
  EXPECT_FALSE(IsRevisitableSkipReason("move_failed"));
}

TEST(SamplesTest, BadRecordsAreNamedWithTheirField) {
  struct Case {
    std::function<void(std::vector<json>&)> edit;
    std::string expected;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Record numbers count from 1; in SyntheticJournal() record 10 is Accepted(0), record 9 Frame(0).
  const std::vector<Case> cases = {
      {[](auto& r) {
         r[9]["joints_rad"] = {0.1, 0.2};
       },
       "journal record 10 (sample_accepted): field \"joints_rad\": expected an array of 6"},
      {[&](auto& r) { r[9]["exposure_time_s"] = nan; }, "record 10 (sample_accepted): field \"exposure_time_s\""},
      {[](auto& r) { r[9]["settle_time_s"] = nullptr; }, "field \"settle_time_s\": expected a finite number"},
      {[](auto& r) { r[9].erase("joint_time_s"); }, "field \"joint_time_s\": missing"},
      {[](auto& r) { r[9]["pose"] = 7; }, "record 10 (sample_accepted): field \"pose\": 7 is outside [0, 3]"},
      {[](auto& r) { r[9]["pose"] = 1.0; }, "field \"pose\": expected an integer"},
      {[](auto& r) { r[9]["role"] = "check"; }, "field \"role\": \"check\" is neither"},
      {[](auto& r) { r[9]["role"] = "verification"; }, "field \"role\": verification but the pose was planned"},
      {[](auto& r) { r[9]["id"] = "p01"; }, "field \"id\": \"p01\" but pose 0 was planned as \"p00\""},
      {[](auto& r) { r[9]["image"] = "../p00.png"; }, "field \"image\": \"../p00.png\" is not"},
      {[](auto& r) { r[9]["image"] = "images/other.png"; }, "has no earlier frame_written record"},
      {[](auto& r) { r[9]["dots"][1]["id"] = 0; }, "field \"dots[1].id\": dot id 0 repeats"},
      {[](auto& r) { r[9]["dots"][0].erase("area"); }, "field \"dots[0]\": missing \"area\""},
      {[](auto& r) { r[9]["sim_clock_s"] = "soon"; }, "field \"sim_clock_s\""},
      {[](auto& r) { r[8]["crc32"] = "0000ABCD"; }, "record 9 (frame_written): field \"crc32\""},
      {[](auto& r) { r[8]["bytes"] = -5; }, "record 9 (frame_written): field \"bytes\""},
      {[](auto& r) { r[5]["from_rad"] = {1.0}; }, "record 6 (move_started): field \"from_rad\""},
      {[](auto& r) { r[0]["num_poses"] = "four"; }, "record 1 (session_started): field \"num_poses\""},
      {[](auto& r) {
         r.insert(r.begin(), json{{"type", "resumed"}, {"time_s", 0.0}});
       },
       "journal record 1 (resumed): field \"type\": a session journal starts with session_started"},
      {[](auto& r) { r.push_back(Started(4)); }, "session_started appears again"},
      {[](auto& r) {
         r.push_back({{"type", 3}});
       },
       "journal record 22: no \"type\" string"},
      {[](auto& r) {
         json again = Planned(1);
         again["joints_rad"][0] = 1.0;
         r.push_back(again);
       },
       "record 22 (pose_planned): field \"pose\": planned again with other values"},
      {[](auto& r) { r.erase(r.begin() + 2, r.begin() + 4); },
       "record 3 (pose_planned): field \"pose\": pose 3 planned before pose 1"},
      {[](auto& r) { r.push_back(Frame(2, 1, "ffffffff")); }, "record 22 (frame_written): field \"image\""},
      {[](auto& r) { r.push_back(Skipped(3, "")); }, "record 22 (sample_skipped): field \"reason\""},
      {[](auto& r) {
         r.push_back({{"type", "fault"}, {"kind", "x"}, {"pose", -1}});
       },
       "record 22 (fault): field \"pose\""},
      {[](auto& r) {
         r.push_back({{"type", "halted"}, {"pose", 1}});
       },
       "record 22 (halted): field \"reason\": missing"},
      {[](auto& r) {
         r.push_back({{"type", "finished"}});
       },
       "record 22 (finished): field \"time_s\": missing"},
  };
  for (const Case& c : cases) {
    std::vector<json> records = SyntheticJournal();
    c.edit(records);
    Result<SessionLog> log = ReadSessionLog(records);
    ASSERT_FALSE(log.ok()) << c.expected;
    EXPECT_EQ(log.status().code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(Contains(log.status().message(), c.expected)) << log.status().message();
  }
  // Planning a pose again identically is harmless.
  std::vector<json> replanned = SyntheticJournal();
  replanned.push_back(Planned(1));
  EXPECT_TRUE(ReadSessionLog(replanned).ok());
  // A pose named before it is planned.
  Result<SessionLog> early = ReadSessionLog({Started(2), Planned(0), Frame(1)});
  ASSERT_FALSE(early.ok());
  EXPECT_TRUE(Contains(early.status().message(), "record 3 (frame_written): field \"pose\": pose 1 is not planned"))
      << early.status().message();
}

// Issue 16: a record with a valid CRC and a dot at u = 1e6 (or joints beyond the robot's limits) passed the
// journal reading and was refused only while writing calibrate's output, naming neither record nor line.
TEST(SamplesTest, SampleContentsAreCheckedAgainstTheCameraAndTheRobotNamingTheLine) {
  CameraIntrinsics camera;
  camera.width_px = 640;
  camera.height_px = 480;
  const RobotModel robot = selfcal::testing::Puma560();
  Result<SessionLog> log = ReadSessionLog(SyntheticJournal());
  ASSERT_TRUE(log.ok()) << log.status().message();
  EXPECT_TRUE(CheckSampleContents(*log, "s/journal.log", camera, robot).ok());
  std::vector<json> forged = SyntheticJournal();
  ASSERT_EQ(forged[9]["type"], "sample_accepted");
  forged[9]["dots"][0]["u"] = 1e6;
  forged[9]["joints_rad"][1] = 10.0;
  forged[19]["dots"][1]["w"] = 0.0;
  log = ReadSessionLog(forged);
  ASSERT_TRUE(log.ok()) << "the per-field checks alone accept it: " << log.status().message();
  const Status status = CheckSampleContents(*log, "s/journal.log", camera, robot);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  for (const std::string part :
       {"s/journal.log:10 (sample_accepted of pose p00): dots[0] (dot 0): centre (1000000, 200.25) px lies outside "
        "the 640x480 image",
        "s/journal.log:10 (sample_accepted of pose p00): joint 2 = 10 rad lies outside its limits",
        "s/journal.log:20 (sample_accepted of pose p02): dots[1] (dot 3): size 0 x 8 px"}) {
    EXPECT_TRUE(Contains(status.message(), part)) << part << " in: " << status.message();
  }
}

TEST(SamplesTest, VerifySampleImages) {
  TempDir dir;
  const std::string path = dir.File("s");
  Result<Session> created = CreateTestSession(path);
  ASSERT_TRUE(created.ok());
  Session& session = created.value();
  const std::string image = "PNG bytes of pose zero";
  const std::string crc = Crc32Hex(Crc32(image));
  ASSERT_TRUE(session.WriteImage("p00.png", image).ok());
  std::vector<json> records = {Started(2), Planned(0), Planned(1), Frame(0, 0, crc, static_cast<int>(image.size())),
                               Accepted(0)};
  for (const json& record : records) ASSERT_TRUE(session.journal().Append(record).ok());
  Result<SessionLog> log = ReadSessionLog(session.journal().records());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_TRUE(VerifySampleImages(session, *log).ok());

  WriteFile(path + "/images/p00.png", "PNG bytes of pose zer0");  // same size, other bytes
  Status bad = VerifySampleImages(session, *log);
  EXPECT_EQ(bad.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(Contains(bad.message(), "images/p00.png (pose 0): CRC-32")) << bad.message();
  WriteFile(path + "/images/p00.png", "short");
  EXPECT_TRUE(Contains(VerifySampleImages(session, *log).message(), "5 bytes, the journal recorded 22"));
  std::filesystem::remove(path + "/images/p00.png");
  EXPECT_TRUE(Contains(VerifySampleImages(session, *log).message(), "images/p00.png (pose 0): missing"));
}

// dots_named_later (acquisition/late_naming.h): the dots are appended to their pose's sample, counted,
// and a record that names no earlier sample or a dot the sample holds is refused naming the record.
TEST(SamplesTest, DotsNamedLaterJoinTheirSample) {
  std::vector<json> records = SyntheticJournal();
  const json later = {{"type", "dots_named_later"},
                      {"pose", 0},
                      {"dots", {{{"id", 7}, {"u", 300.0}, {"v", 120.0}, {"area", 60.0}, {"w", 9.0}, {"h", 9.0}}}}};
  records.push_back(later);
  Result<SessionLog> read = ReadSessionLog(records);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  const AcceptedSample& first = *read->accepted[0];
  ASSERT_EQ(first.dots.size(), 3u);
  EXPECT_EQ(first.dots[2].id, 7);
  EXPECT_EQ(first.dots[2].u_px, 300.0);
  EXPECT_EQ(first.named_later, 1);
  EXPECT_EQ(read->unknown_records, 1u);  // the synthetic journal's own unknown record only

  std::vector<json> no_sample = SyntheticJournal();
  json bad = later;
  bad["pose"] = 1;  // pose 1 was skipped
  no_sample.push_back(bad);
  Result<SessionLog> refused = ReadSessionLog(no_sample);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("(dots_named_later): field \"pose\": pose 1 has no earlier sample_accepted"),
            std::string::npos)
      << refused.status().message();

  std::vector<json> held = SyntheticJournal();
  bad = later;
  bad["dots"][0]["id"] = 3;  // sample 0 holds dot 3
  held.push_back(bad);
  refused = ReadSessionLog(held);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("dot 3 is already in the sample of pose 0"), std::string::npos)
      << refused.status().message();
}

}  // namespace
}  // namespace selfcal::session
