// The live view (liveview) on a simulated image-mode session (acquisition's loop on simulation's cell)
// under Xvfb: the window read back from the X server after the run shows the last accepted frame with a
// cross in the tracked colour at the truth projection of every dot, the pose headline, and the image
// itself between the dots. The screenshot is kept as a test artifact (its path is printed).
#include <chrono>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>
#include <visp3/io/vpImageIo.h>

#include "liveview/live_view.h"
#include "simulation/sim_session_test_harness.h"
#include "support/xvfb.h"

namespace selfcal {
namespace {

bool ColorNear(const vpImage<vpRGBa>& image, const Eigen::Vector2d& uv, const vpColor& color, int radius) {
  return testing::ColorNear(image, uv.x(), uv.y(), color, radius);
}

TEST(LiveViewSession, UnderXvfbTheWindowShowsTheTrackedDotsAtTheirTruePixelsAndThePose) {
  testing::XvfbServer xvfb;
  std::string why;
  if (!xvfb.Start(&why)) GTEST_SKIP() << "no X server for the live view: " << why;
  testing::ScopedDisplay display(xvfb.display());
  const std::string unavailable = liveview::DisplayUnavailableReason();
  if (!unavailable.empty()) GTEST_SKIP() << "the live view cannot draw: " << unavailable;
  liveview::LiveViewOptions options;
  options.title = "selfcal live view test";
  Result<std::unique_ptr<liveview::LiveView>> opened = liveview::OpenLiveView(liveview::LiveViewMode::kOn, options);
  ASSERT_TRUE(opened.ok()) << opened.status().message();
  liveview::LiveView& view = **opened;

  simulation::Harness h(5);
  acquisition::RunContext context = h.Context();
  double last_exposure_s = 0;
  context.observe = [&](const acquisition::FrameView& frame) {
    view.Show(frame);
    last_exposure_s = frame.frame->exposure_time_s;
  };
  const auto start = std::chrono::steady_clock::now();
  const acquisition::RunReport report = acquisition::RunSession(h.plan, context, h.options);
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_GE(view.frames_drawn(), 10);  // 5 settled + 5 accepted, and some of the moves
  std::printf("live view: %d frames drawn, %d frames of moves not redrawn, session %.1f s (%d frames grabbed)\n",
              view.frames_drawn(), view.frames_throttled(), run_s, report.frames_grabbed);

  Result<vpImage<vpRGBa>> screenshot = view.Snapshot();
  ASSERT_TRUE(screenshot.ok()) << screenshot.status().message();
  const std::filesystem::path artifacts = std::filesystem::path(SELFCAL_TEST_ARTIFACTS_DIR);
  std::filesystem::create_directories(artifacts);
  const std::string png = (artifacts / "live_view.png").string();
  vpImageIo::write(*screenshot, png);
  std::printf("live view screenshot: %s\n", png.c_str());
  ASSERT_TRUE(std::filesystem::exists(png));

  // The last view is pose p04's accepted sample: every dot it was accepted with in the tracked (green) or named (cyan)
  // colour at the truth projection, within 2 px (the cross is 15 px wide, 2 px thick).
  const session::SessionLog log = h.Log();
  ASSERT_TRUE(log.accepted[4]);
  const sim::SimTruth& truth = h.cell.world->truth;
  const Rigid3 cam_from_base =
      BaseFromCam(truth.nominal, truth.rho_true, h.cell.robot->JointsAt(last_exposure_s)).Inverse();
  const vpImage<vpRGBa>& shot = *screenshot;
  ASSERT_EQ(shot.getWidth(), truth.camera_true.width_px);
  int marked = 0;
  // The dots named later, in the recorded frames once the session ended, were never in a live view.
  const std::vector<session::SampleDot>& dots = log.accepted[4]->dots;
  for (size_t k = 0; k + static_cast<size_t>(log.accepted[4]->named_later) < dots.size(); ++k) {
    const session::SampleDot& d = dots[k];
    const auto uv = Project(truth.camera_true, cam_from_base * truth.dots_in_base[d.id]);
    const bool drawn = ColorNear(shot, *uv, vpColor::green, 2) || ColorNear(shot, *uv, vpColor::cyan, 2);
    EXPECT_TRUE(drawn) << "dot " << d.id << " at " << uv->transpose();
    marked += drawn ? 1 : 0;
  }
  EXPECT_GE(marked, 20);
  // The headline in yellow at the top, and between the dots the grey image itself (not a blank window).
  int yellow = 0, grey = 0, levels_seen = 0;
  std::vector<bool> level(256, false);
  for (unsigned r = 0; r < shot.getHeight(); ++r) {
    for (unsigned c = 0; c < shot.getWidth(); ++c) {
      const vpRGBa& p = shot[r][c];
      if (r < 24 && p.R == 255 && p.G == 255 && p.B == 0) ++yellow;
      if (p.R == p.G && p.G == p.B) {
        ++grey;
        if (!level[p.R]) ++levels_seen, level[p.R] = true;
      }
    }
  }
  EXPECT_GT(yellow, 60);
  EXPECT_GT(grey, static_cast<int>(shot.getSize() * 9 / 10));
  EXPECT_GT(levels_seen, 50);  // the rendered scene: bright background, dark dots, noise
}

}  // namespace
}  // namespace selfcal
