// The live view on its own: the modes, the refusal without a display, and under Xvfb the overlay read
// back from the X server (each dot's cross in its state's colour at its pixel, the headline drawn, the
// image itself where nothing is drawn) and the throttling of a move's frames.
#include "liveview/live_view.h"

#include <cstdlib>
#include <optional>

#include <gtest/gtest.h>

#include "support/xvfb.h"

namespace selfcal::liveview {
namespace {

using testing::ColorNear;
using testing::ScopedDisplay;

TEST(LiveView, ParsesTheThreeModesAndRefusesOthers) {
  EXPECT_EQ(*ParseLiveViewMode("auto"), LiveViewMode::kAuto);
  EXPECT_EQ(*ParseLiveViewMode("on"), LiveViewMode::kOn);
  EXPECT_EQ(*ParseLiveViewMode("off"), LiveViewMode::kOff);
  const Result<LiveViewMode> bad = ParseLiveViewMode("yes");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "--live-view must be auto, on or off, not \"yes\"");
}

TEST(LiveView, WithoutADisplayOnIsRefusedAutoIsOffWithoutAnError) {
  ScopedDisplay no_display("");
  std::string note;
  const Result<std::unique_ptr<LiveView>> on = OpenLiveView(LiveViewMode::kOn, LiveViewOptions(), &note);
  ASSERT_FALSE(on.ok());
  EXPECT_EQ(on.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(on.status().message().find("--live-view on: $DISPLAY is not set"), std::string::npos)
      << on.status().message();
  EXPECT_NE(on.status().message().find("--live-view off"), std::string::npos);
  Result<std::unique_ptr<LiveView>> automatic = OpenLiveView(LiveViewMode::kAuto, LiveViewOptions(), &note);
  ASSERT_TRUE(automatic.ok());
  EXPECT_EQ(*automatic, nullptr);
  EXPECT_EQ(note, "live view off: $DISPLAY is not set");
  ::setenv("DISPLAY", ":4093", 1);  // no server there
  automatic = OpenLiveView(LiveViewMode::kAuto, LiveViewOptions(), &note);
  ASSERT_TRUE(automatic.ok());
  EXPECT_EQ(*automatic, nullptr);
  const std::string reason = DisplayUnavailableReason();
  EXPECT_EQ(note, "live view off: " + reason);
  EXPECT_TRUE(reason == "cannot open the X display :4093" ||
              reason == "this build has no X11 display (ViSP without X11)")
      << reason;
  Result<std::unique_ptr<LiveView>> off = OpenLiveView(LiveViewMode::kOff, LiveViewOptions(), &note);
  ASSERT_TRUE(off.ok());
  EXPECT_EQ(*off, nullptr);
}

int CountColor(const vpImage<vpRGBa>& image, const vpColor& color, int row0, int row1, int col0, int col1) {
  int n = 0;
  for (int r = row0; r < row1; ++r) {
    for (int c = col0; c < col1; ++c) {
      const vpRGBa& p = image[r][c];
      n += p.R == color.R && p.G == color.G && p.B == color.B ? 1 : 0;
    }
  }
  return n;
}

// An Xvfb server with $DISPLAY on it for each test; skipped without Xvfb or an X11 build.
class LiveViewUnderXvfb : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!xvfb_.Start(&why)) GTEST_SKIP() << "no X server for the live view: " << why;
    display_.emplace(xvfb_.display());
    if (const std::string why_not = DisplayUnavailableReason(); !why_not.empty()) GTEST_SKIP() << why_not;
  }
  testing::XvfbServer xvfb_;
  std::optional<ScopedDisplay> display_;
};

TEST_F(LiveViewUnderXvfb, DrawsEachDotInItsStatesColourAndThePose) {
  Result<std::unique_ptr<LiveView>> opened = OpenLiveView(LiveViewMode::kOn, LiveViewOptions());
  ASSERT_TRUE(opened.ok()) << opened.status().message();
  LiveView& view = **opened;

  capture::Frame frame;
  frame.image.resize(480, 640, 100);  // a flat grey frame: every coloured pixel is overlay
  acquisition::FrameView shown;
  shown.frame = &frame;
  shown.phase = acquisition::FramePhase::kSettled;
  shown.pose = 3;
  shown.pose_id = "p03";
  shown.num_poses = 12;
  shown.dots = {{0, {100.3, 200.6}, acquisition::ViewDotState::kTracked},
                {7, {400.0, 120.0}, acquisition::ViewDotState::kNamed},
                {9, {520.5, 300.2}, acquisition::ViewDotState::kLost},
                {12, {250.0, 380.0}, acquisition::ViewDotState::kCandidate}};
  view.Show(shown);
  ASSERT_EQ(view.frames_drawn(), 1);
  Result<vpImage<vpRGBa>> snapshot = view.Snapshot();
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().message();
  const vpImage<vpRGBa>& image = *snapshot;
  ASSERT_EQ(image.getWidth(), 640u);
  ASSERT_EQ(image.getHeight(), 480u);
  EXPECT_TRUE(ColorNear(image, 100.3, 200.6, vpColor::green));
  EXPECT_TRUE(ColorNear(image, 400.0, 120.0, vpColor::cyan));
  EXPECT_TRUE(ColorNear(image, 520.5, 300.2, vpColor::red));
  EXPECT_TRUE(ColorNear(image, 250.0, 380.0, vpColor::yellow));
  // Nothing drawn away from the dots and the text: the frame's own grey.
  EXPECT_EQ(image[240][320].R, 100);
  EXPECT_EQ(image[240][320].G, 100);
  EXPECT_FALSE(ColorNear(image, 320, 240, vpColor::green, 20));
  // The headline ("pose 4/12 p03: settled, ...") in yellow in the top rows; the legend in white at the bottom.
  EXPECT_GT(CountColor(image, vpColor::yellow, 0, 24, 0, 320), 40);
  EXPECT_GT(CountColor(image, vpColor::white, 455, 480, 0, 400), 40);

  // A move's frames: at most 15 a second are drawn; the settled frame always is.
  shown.phase = acquisition::FramePhase::kMoving;
  for (int i = 0; i < 20; ++i) view.Show(shown);
  EXPECT_LE(view.frames_drawn(), 3);
  EXPECT_GE(view.frames_throttled(), 18);
  const int before = view.frames_drawn();
  shown.phase = acquisition::FramePhase::kSkipped;
  shown.detail = "too_few_dots";
  view.Show(shown);
  EXPECT_EQ(view.frames_drawn(), before + 1);
  snapshot = view.Snapshot();
  ASSERT_TRUE(snapshot.ok());
  EXPECT_GT(CountColor(*snapshot, vpColor::red, 0, 24, 0, 400), 40);  // "... SKIPPED (too_few_dots)" in red
}

// The X server going away (or the window manager killing the window's client) turns the view off with
// a line for the operator; the process goes on (Xlib's default would exit mid-session).
TEST_F(LiveViewUnderXvfb, ALostXConnectionTurnsTheViewOffAndTheProcessGoesOn) {
  std::vector<std::string> lines;
  LiveViewOptions options;
  options.log = [&lines](const std::string& line) { lines.push_back(line); };
  LiveView view(options);
  capture::Frame frame;
  frame.image.resize(240, 320, 100);
  acquisition::FrameView shown;
  shown.frame = &frame;
  shown.phase = acquisition::FramePhase::kSettled;
  shown.pose_id = "p00";
  shown.num_poses = 2;
  view.Show(shown);
  ASSERT_EQ(view.frames_drawn(), 1);
  ASSERT_FALSE(view.failed());
  xvfb_.Stop();
  for (int i = 0; i < 3 && !view.failed(); ++i) view.Show(shown);
  EXPECT_TRUE(view.failed());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "live view off: the connection to the X display was lost (the session goes on)");
  view.Show(shown);  // nothing more happens
  EXPECT_EQ(lines.size(), 1u);
  EXPECT_FALSE(view.Snapshot().ok());
}

}  // namespace
}  // namespace selfcal::liveview
