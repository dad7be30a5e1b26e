#include "capture/frame_checks.h"

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"

namespace selfcal::capture {
namespace {

using testing::Contains;
using testing::TestImage;
using testing::Uniform;

TEST(CaptureError, TravelsInTheStatusWithItsExitCode) {
  const Status s = CaptureFailure(CaptureError::kTimeout, "camera /dev/video0: no frame");
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kTimeout);
  EXPECT_EQ(s.code(), ErrorCode::kHardware);
  EXPECT_EQ(CaptureFailure(CaptureError::kSequenceCorrupt, "x").code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(CaptureFailure(CaptureError::kSequenceEnd, "x").code(), ErrorCode::kDegenerateData);
  EXPECT_EQ(CaptureErrorOf(Status::Ok()), CaptureError::kNone);
  EXPECT_EQ(CaptureErrorOf(Status::Error(ErrorCode::kInvalidInput, "not from capture").WithDetail("io", 6)),
            CaptureError::kNone);
  EXPECT_STREQ(CaptureErrorName(CaptureError::kDeviceBusy), "device_busy");
  EXPECT_THROW(CaptureFailure(CaptureError::kNone, "x"), InvalidArgument);
}

TEST(FrameChecks, StatsOfAKnownImage) {
  // Half the pixels 0, half 200: mean 100, standard deviation 100, black fraction 0.5.
  vpImage<unsigned char> image = Uniform(10, 4, 0);
  for (int v = 0; v < 4; ++v) {
    for (int u = 5; u < 10; ++u) image[v][u] = 200;
  }
  const FrameStats s = ComputeFrameStats(image, false);
  EXPECT_EQ(s.width_px, 10);
  EXPECT_EQ(s.height_px, 4);
  EXPECT_DOUBLE_EQ(s.mean_grey, 100.0);
  EXPECT_DOUBLE_EQ(s.stddev_grey, 100.0);
  EXPECT_DOUBLE_EQ(s.black_fraction, 0.5);
  EXPECT_DOUBLE_EQ(s.saturated_fraction, 0.0);
  EXPECT_EQ(s.laplacian_variance, -1);
}

TEST(FrameChecks, AcceptsANormalFrame) {
  EXPECT_TRUE(CheckFrame(TestImage(64, 48, 0, 1), FrameCheckOptions(), "cam").ok());
}

TEST(FrameChecks, RefusesBlackSaturatedFlatAndEmptyFramesNamingTheSource) {
  const FrameCheckOptions options;
  struct Case {
    vpImage<unsigned char> image;
    const char* why;
  };
  vpImage<unsigned char> mostly_black = TestImage(64, 48, 0, 1);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 40; ++u) mostly_black[v][u] = 0;  // 62.5 % black, mean still above the floor
  }
  vpImage<unsigned char> mostly_saturated = TestImage(64, 48, 0, 1);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 40; ++u) mostly_saturated[v][u] = 255;
  }
  const std::vector<Case> cases = {{Uniform(64, 48, 0), "all black"},
                                   {Uniform(64, 48, 3), "all black"},
                                   {Uniform(64, 48, 255), "saturated"},
                                   {Uniform(64, 48, 128), "no contrast"},
                                   {mostly_black, "pixels are 0"},
                                   {mostly_saturated, "pixels are 255"},
                                   {vpImage<unsigned char>(), "empty or truncated"}};
  for (const Case& c : cases) {
    const Status s = CheckFrame(c.image, options, "/dev/video7");
    EXPECT_EQ(CaptureErrorOf(s), CaptureError::kBadFrame) << c.why;
    EXPECT_TRUE(Contains(s.message(), "/dev/video7")) << s.message();
    EXPECT_TRUE(Contains(s.message(), c.why)) << s.message();
  }
}

TEST(FrameChecks, LaplacianVarianceOfAStepEdgeIsExact) {
  // A vertical step 50 -> 150 between columns 31 and 32 of a 64-wide image: the Laplacian is +100 in
  // column 31 and -100 in column 32, 0 elsewhere, so over the 62 interior columns its mean is 0 and its
  // variance 2 * 100^2 / 62.
  vpImage<unsigned char> step = Uniform(64, 20, 50);
  for (int v = 0; v < 20; ++v) {
    for (int u = 32; u < 64; ++u) step[v][u] = 150;
  }
  EXPECT_NEAR(LaplacianVariance(step), 2 * 100.0 * 100.0 / 62, 1e-9);
  // A linear ramp 50, 75, 100, 125, 150 over columns 30..34 instead of the step.
  vpImage<unsigned char> ramp = step;
  for (int v = 0; v < 20; ++v) {
    ramp[v][31] = 75;
    ramp[v][32] = 100;
    ramp[v][33] = 125;
  }
  // Columns 30..34 now carry Laplacians +25, 0, 0, 0, -25: variance 2 * 25^2 / 62.
  EXPECT_NEAR(LaplacianVariance(ramp), 2 * 25.0 * 25.0 / 62, 1e-9);

  FrameCheckOptions options;
  options.min_stddev_grey = 1;
  options.min_laplacian_variance = 100;  // between the ramp's 20.2 and the step's 322.6
  EXPECT_TRUE(CheckFrame(step, options, "cam").ok());
  const Status blurred = CheckFrame(ramp, options, "cam");
  EXPECT_EQ(CaptureErrorOf(blurred), CaptureError::kBadFrame);
  EXPECT_TRUE(Contains(blurred.message(), "blurred")) << blurred.message();
}

TEST(FrameChecks, OrderNeedsAdvancingSequenceAndTime) {
  Frame f;
  f.source = "cam";
  f.sequence = 5;
  f.exposure_time_s = 2.0;
  EXPECT_TRUE(CheckFrameOrder(-1, 0.0, f).ok());  // first frame
  EXPECT_TRUE(CheckFrameOrder(3, 1.9, f).ok());   // a gap (dropped frame 4) is allowed
  const Status duplicate = CheckFrameOrder(5, 1.9, f);
  EXPECT_EQ(CaptureErrorOf(duplicate), CaptureError::kBadFrame);
  EXPECT_TRUE(Contains(duplicate.message(), "duplicated")) << duplicate.message();
  EXPECT_TRUE(Contains(CheckFrameOrder(6, 1.9, f).message(), "went back"));
  EXPECT_TRUE(Contains(CheckFrameOrder(4, 2.0, f).message(), "not after"));
}

TEST(FrameChecks, OptionsValidateListsEveryProblem) {
  FrameCheckOptions o;
  EXPECT_EQ(o.Validate(), "");
  o.min_mean_grey = 300;
  o.max_saturated_fraction = 2;
  o.min_laplacian_variance = -1;
  const std::string problems = o.Validate();
  EXPECT_TRUE(Contains(problems, "min_mean_grey = 300"));
  EXPECT_TRUE(Contains(problems, "max_saturated_fraction = 2"));
  EXPECT_TRUE(Contains(problems, "min_laplacian_variance = -1"));
}

// A timeout's words: the settle time it waited for, or none for the pre-flight frame of Open (any frame), whose
// bound of -1e300 was printed in full digits.
TEST(FrameSourceWords, ATimeoutNamesTheSettleTimeOrNothingForAnyFrame) {
  EXPECT_EQ(ExposedAtOrAfterWords(kAnyFrame), "");
  EXPECT_EQ(ExposedAtOrAfterWords(12.5), "exposed at or after 12.500000 s ");
}

}  // namespace
}  // namespace selfcal::capture
