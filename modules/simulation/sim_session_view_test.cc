// What the operator sees of a simulated session (issue 14 item 5): the frames handed to a live view
// (RunContext::observe) with their phases and dots against the truth, and the rejected frames of skipped
// poses kept in images/rejected/, journaled, named by the skip, readable, and left alone by a resume.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <gtest/gtest.h>

#include "base/crc32.h"
#include "capture/png_codec.h"
#include "session/session_snapshot.h"
#include "simulation/sim_session_test_harness.h"
#include "tracking/dot_detector.h"

namespace selfcal::simulation {
namespace {

// Counts the views by phase and keeps the dots of the last one.
struct ViewRecorder {
  std::map<acquisition::FramePhase, int> phases;
  std::vector<acquisition::ViewDot> last_dots;
  double last_exposure_s = 0;
  std::string last_detail;
  void operator()(const acquisition::FrameView& view) {
    ++phases[view.phase];
    last_dots = view.dots;
    last_exposure_s = view.frame->exposure_time_s;
    last_detail = view.detail;
  }
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SessionView, EveryFrameIsShownWithItsPhaseAndTheDotsWhereTheTruthPutsThem) {
  Harness h(4);
  auto recorder = std::make_shared<ViewRecorder>();
  acquisition::RunContext context = h.Context();
  context.observe = [recorder](const acquisition::FrameView& view) { (*recorder)(view); };
  const acquisition::RunReport report = acquisition::RunSession(h.plan, context, h.options);
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_EQ(recorder->phases[acquisition::FramePhase::kSettled], 4);
  EXPECT_EQ(recorder->phases[acquisition::FramePhase::kAccepted], 4);
  EXPECT_EQ(recorder->phases[acquisition::FramePhase::kSkipped], 0);
  EXPECT_GT(recorder->phases[acquisition::FramePhase::kMoving], 10);  // every frame tracked during the moves
  // The last view (pose 3 accepted): its tracked dots where the true arm and camera project them.
  const sim::SimTruth& truth = h.cell.world->truth;
  const Rigid3 cam_from_base =
      BaseFromCam(truth.nominal, truth.rho_true, h.cell.robot->JointsAt(recorder->last_exposure_s)).Inverse();
  ASSERT_GE(recorder->last_dots.size(), 20u);
  for (const acquisition::ViewDot& d : recorder->last_dots) {
    if (d.state == acquisition::ViewDotState::kLost || d.state == acquisition::ViewDotState::kCandidate) continue;
    const auto uv = Project(truth.camera_true, cam_from_base * truth.dots_in_base[d.id]);
    EXPECT_LT((*uv - d.centroid_px).norm(), 1.0) << "dot " << d.id;
  }
}

TEST(SessionView, SkippedPosesKeepTheirRejectedFramesBesideTheImages) {
  Harness h(4);
  h.options.min_dots = 10000;  // every pose: too few dots
  auto recorder = std::make_shared<ViewRecorder>();
  acquisition::RunContext context = h.Context();
  context.observe = [recorder](const acquisition::FrameView& view) { (*recorder)(view); };
  const acquisition::RunReport report = acquisition::RunSession(h.plan, context, h.options);
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kTooFewSamples) << report.message;  // no sample at all
  EXPECT_EQ(report.skips.at("too_few_dots"), 4);
  EXPECT_EQ(recorder->phases[acquisition::FramePhase::kSkipped], 4);
  EXPECT_EQ(recorder->last_detail, "too_few_dots");
  const session::SessionLog log = h.Log();
  EXPECT_EQ(log.NumAccepted(), 0);
  EXPECT_TRUE(log.frames.empty());  // no frame_written: nothing for calibrate
  ASSERT_EQ(log.rejected.size(), 4u);
  for (int pose = 0; pose < 4; ++pose) {
    ASSERT_EQ(log.skips[pose].size(), 1u);
    const session::SkippedSample& skip = log.skips[pose][0];
    const std::string expected = "images/rejected/" + h.plan[pose].id + "_0.png";
    ASSERT_EQ(skip.rejected_images, std::vector<std::string>{expected});
    const session::FrameRejected& frame = log.rejected.at(expected);
    EXPECT_EQ(frame.pose, pose);
    EXPECT_EQ(frame.reason, "too_few_dots");
    const std::string bytes = ReadFile(h.session->path() + "/" + expected);
    EXPECT_EQ(bytes.size(), frame.bytes);
    EXPECT_EQ(Crc32(bytes), frame.crc32);
    Result<vpImage<unsigned char>> image = capture::DecodeGreyPng(bytes, expected);
    ASSERT_TRUE(image.ok()) << image.status().message();
    EXPECT_EQ(image->getWidth(), h.cell.world->truth.camera_true.width_px);
    // The frame the operator gets shows the scene: its dots are there, only fewer than min_dots.
    EXPECT_GT(tracking::DetectDots(*image, h.options.detector).dots.size(), 20u) << expected;
  }
  // The read-only reader sees no unrecorded image; a resume moves none to orphans/.
  Result<session::SessionSnapshot> snapshot = session::ReadSession(h.session->path());
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().message();
  EXPECT_TRUE(snapshot->unrecorded_images.empty());
  const std::string path = h.session->path();
  h.session.reset();
  Result<session::Session> reopened = session::OpenSession(path, {}, false);
  ASSERT_TRUE(reopened.ok()) << reopened.status().message();
  EXPECT_TRUE(reopened->open_report().orphans.empty());
  EXPECT_TRUE(std::filesystem::exists(path + "/images/rejected/p00_0.png"));
}

TEST(SessionView, AnUnrecordedRejectedFrameBecomesAnOrphanOnResume) {
  Harness h(4);
  ASSERT_TRUE(h.session->WriteRejectedImage("p01_0.png", "not journaled").ok());
  const std::string path = h.session->path();
  Result<session::SessionSnapshot> snapshot = session::ReadSession(path);
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().message();
  EXPECT_EQ(snapshot->unrecorded_images, std::vector<std::string>{"images/rejected/p01_0.png"});
  h.session.reset();
  Result<session::Session> reopened = session::OpenSession(path, {}, false);
  ASSERT_TRUE(reopened.ok()) << reopened.status().message();
  EXPECT_EQ(reopened->open_report().orphans, std::vector<std::string>{"orphans/rejected_p01_0.png"});
  EXPECT_FALSE(std::filesystem::exists(path + "/images/rejected/p01_0.png"));
}

}  // namespace
}  // namespace selfcal::simulation
