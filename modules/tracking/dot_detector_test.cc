#include "tracking/dot_detector.h"

#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "tracking/tracking_test_util.h"

namespace selfcal::tracking {
namespace {

using testing::Disc;
using testing::Render;
using testing::Shape;

constexpr double kBackground = 200;
constexpr double kDot = 40;

// Discs on a jittered lattice (spacing 30 px) with radii in [r_min, r_max]; centres are truth.
struct DiscField {
  std::vector<Eigen::Vector2d> centres;
  std::vector<double> radii;
};

DiscField MakeField(int cols, int rows, double r_min, double r_max, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> jitter(-3.0, 3.0), radius(r_min, r_max);
  DiscField f;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      f.centres.emplace_back(30.0 + 30.0 * c + jitter(*rng), 30.0 + 30.0 * r + jitter(*rng));
      f.radii.push_back(radius(*rng));
    }
  }
  return f;
}

std::vector<Shape> Discs(const DiscField& f, double level = kDot) {
  std::vector<Shape> shapes;
  for (size_t k = 0; k < f.centres.size(); ++k) shapes.push_back(Disc(f.centres[k], f.radii[k], level));
  return shapes;
}

// Index of the detection nearest to p, and its distance.
std::pair<int, double> Nearest(const DetectionReport& r, const Eigen::Vector2d& p) {
  int best = -1;
  double d = 1e9;
  for (size_t k = 0; k < r.dots.size(); ++k) {
    const double e = (r.dots[k].centroid_px - p).norm();
    if (e < d) {
      d = e;
      best = static_cast<int>(k);
    }
  }
  return {best, d};
}

TEST(DotDetector, ValidateNamesEveryProblem) {
  DotDetectorOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.threshold_mode = ThresholdMode::kFixed;
  o.fixed_threshold = 300;
  o.duplicate_distance_px = -1;
  o.acceptance.min_area_px2 = 1;
  o.acceptance.max_edge_coverage = 2;
  o.acceptance.min_axis_ratio = 2;
  o.acceptance.ellipse_shape_precision = 1.5;
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  for (const char* key : {"fixed_threshold", "duplicate_distance_px", "min_area_px2", "min_axis_ratio",
                          "ellipse_shape_precision", "max_edge_coverage"}) {
    EXPECT_NE(s.message().find(key), std::string::npos) << key << " missing from:\n" << s.message();
  }
  EXPECT_THROW(DetectDots(vpImage<unsigned char>(10, 10, 200), o), InvalidArgument);
  EXPECT_THROW(DetectDots(vpImage<unsigned char>(), DotDetectorOptions()), InvalidArgument);
}

TEST(DotDetector, ThresholdsSplitTwoLevels) {
  vpImage<unsigned char> img(20, 20, 200);
  for (unsigned v = 0; v < 10; ++v) {
    for (unsigned u = 0; u < 20; ++u) img[v][u] = 40;
  }
  const int t = OtsuThreshold(img);
  EXPECT_GE(t, 40);
  EXPECT_LT(t, 200);
  vpImage<unsigned char> square(20, 20, 200);
  for (unsigned v = 8; v < 12; ++v) {
    for (unsigned u = 8; u < 12; ++u) square[v][u] = 40;
  }
  EXPECT_EQ(LocalThreshold(square, PixelBox{8, 8, 11, 11}), (40 + 200) / 2);
  EXPECT_EQ(ChooseThreshold(img, ThresholdMode::kFixed, 77), 77);
  EXPECT_EQ(ChooseThreshold(img, ThresholdMode::kLocal, 77), -1);
}

// The three threshold modes find the same dots on a uniform background.
TEST(DotDetector, ThresholdModesAgreeOnUniformBackground) {
  std::mt19937_64 rng(12);
  const DiscField f = MakeField(10, 8, 3.0, 8.0, &rng);
  const vpImage<unsigned char> img = Render(340, 280, kBackground, Discs(f), 8, 1.0, 13);
  for (const ThresholdMode mode : {ThresholdMode::kLocal, ThresholdMode::kOtsu, ThresholdMode::kFixed}) {
    DotDetectorOptions o;
    o.threshold_mode = mode;
    o.fixed_threshold = 120;
    const DetectionReport r = DetectDots(img, o);
    ASSERT_EQ(r.dots.size(), f.centres.size()) << static_cast<int>(mode) << ": " << r.rejections.ToString();
    for (size_t k = 0; k < f.centres.size(); ++k) EXPECT_LT(Nearest(r, f.centres[k]).second, 0.08);
  }
}

// Every rendered disc found exactly once, nothing else, area and centroid as rendered.
TEST(DotDetector, FindsEveryRenderedDisc) {
  std::mt19937_64 rng(11);
  const DiscField f = MakeField(20, 15, 3.0, 8.0, &rng);
  const vpImage<unsigned char> img = Render(640, 480, kBackground, Discs(f), 8, 1.0, 12);
  const DetectionReport r = DetectDots(img, DotDetectorOptions());
  EXPECT_EQ(r.dots.size(), f.centres.size()) << r.rejections.ToString();
  EXPECT_EQ(r.rejections.Total(), 0) << r.rejections.ToString();
  EXPECT_EQ(r.candidates, static_cast<int>(r.dots.size()) + r.rejections.Total());
  EXPECT_EQ(r.threshold, -1);  // kLocal: one per dot
  std::vector<int> hits(r.dots.size(), 0);
  for (size_t k = 0; k < f.centres.size(); ++k) {
    const auto [idx, dist] = Nearest(r, f.centres[k]);
    ASSERT_GE(idx, 0);
    ++hits[static_cast<size_t>(idx)];
    // Refined centroid: noise 1 grey level gives ~0.01 px (see CentroidAccuracyOnAntiAliasedDiscs).
    EXPECT_LT(dist, 0.08) << "disc " << k << " r=" << f.radii[k];
    const DotDetection& d = r.dots[static_cast<size_t>(idx)];
    EXPECT_TRUE(d.refined);
    // Half way between the darkest pixel (the dot level for r >= 3) and the background.
    EXPECT_NEAR(d.threshold, 0.5 * (kDot + kBackground), 5.0);
    // Pixels darker than the threshold (about half way) cover the disc to within one perimeter * 0.5 px.
    const double area = M_PI * f.radii[k] * f.radii[k];
    EXPECT_NEAR(d.area_px2, area, M_PI * f.radii[k] + 2) << "disc " << k;
    EXPECT_NEAR(d.contrast, kBackground - kDot, 30);
    EXPECT_GT(d.semi_minor_px / d.semi_major_px, 0.75);  // pixelised polygon of a 3 px disc: ~0.8
  }
  for (int h : hits) EXPECT_EQ(h, 1);
}

// The binarised centre of gravity against the intensity-weighted refinement on anti-aliased discs
// (16 x 16 supersampling), without and with pixel noise.
TEST(DotDetector, CentroidAccuracyOnAntiAliasedDiscs) {
  for (const double sigma : {0.0, 2.0}) {
    double sum_cog = 0, sum_ref = 0, sum_pred = 0;
    int n = 0;
    for (int image = 0; image < 4; ++image) {
      std::mt19937_64 rng(100 + image);
      const DiscField f = MakeField(20, 15, 3.0, 8.0, &rng);
      const vpImage<unsigned char> img =
          Render(640, 480, kBackground, Discs(f), 16, sigma, 200 + static_cast<std::uint64_t>(image));
      const DetectionReport r = DetectDots(img, DotDetectorOptions());
      ASSERT_EQ(r.dots.size(), f.centres.size()) << "sigma " << sigma << " image " << image << ": " << r.rejections.ToString();
      for (size_t k = 0; k < f.centres.size(); ++k) {
        const auto [idx, dist] = Nearest(r, f.centres[k]);
        const DotDetection& d = r.dots[static_cast<size_t>(idx)];
        sum_cog += (d.cog_binary_px - f.centres[k]).squaredNorm();
        sum_ref += (d.centroid_px - f.centres[k]).squaredNorm();
        // Predicted variance (both axes) of a weighted centroid from independent pixel noise sigma over the
        // window (bbox + 2 px): sum_p sigma^2 |p - c|^2 / (sum_p w_p)^2.
        const double half = f.radii[k] + 2.5;
        const double window_moment = 4.0 * half * half * (2.0 * half * half / 3.0);  // integral |p - c|^2
        const double weight = (kBackground - kDot) * M_PI * f.radii[k] * f.radii[k];
        sum_pred += sigma * sigma * window_moment / (weight * weight);
        ++n;
      }
    }
    const double rms_cog = std::sqrt(sum_cog / n), rms_ref = std::sqrt(sum_ref / n);
    const double rms_pred = std::sqrt(sum_pred / n);
    std::cout << "[ centroid ] noise sigma " << sigma << " grey, " << n << " discs r 3-8 px: RMS error vpDot2 CoG "
              << rms_cog << " px, intensity-weighted " << rms_ref << " px (noise prediction " << rms_pred << " px)\n";
    // Floor of the refinement without noise: 8-bit rounding and the 16 x 16 coverage quantisation, a few
    // thousandths of a pixel; with noise the prediction above plus that floor.
    EXPECT_LT(rms_ref, 2.0 * rms_pred + 0.01);
    EXPECT_LT(rms_ref, 0.5 * rms_cog);
  }
}

// The moment ellipse of a rendered ellipse: axes (the dark pixels cover the ellipse to within the pixel
// grid) and the angle convention (from +u towards +v).
TEST(DotDetector, MomentEllipseOfRenderedEllipse) {
  for (const double angle_deg : {0.0, 30.0, -60.0, 90.0}) {
    const double angle = angle_deg * M_PI / 180;
    const vpImage<unsigned char> img =
        Render(200, 200, kBackground, {testing::Ellipse({100.3, 99.6}, 12.0, 6.0, angle, kDot)}, 8);
    const DetectionReport r = DetectDots(img, DotDetectorOptions());
    ASSERT_EQ(r.dots.size(), 1u) << r.rejections.ToString();
    const DotDetection& d = r.dots[0];
    EXPECT_NEAR(d.semi_major_px, 12.0, 0.2);
    EXPECT_NEAR(d.semi_minor_px, 6.0, 0.2);
    double diff = std::remainder(d.angle_rad - angle, M_PI);
    EXPECT_NEAR(diff, 0.0, 2.0 * M_PI / 180) << "angle " << angle_deg;
    EXPECT_NEAR(d.fill_ratio, 1.0, 0.05);
    EXPECT_NEAR(d.centroid_px.x(), 100.3, 0.02);
    EXPECT_NEAR(d.centroid_px.y(), 99.6, 0.02);
  }
}

// D2: dots cut by the image edge (their outermost pixels fully dark) are refused and counted; a dot whose
// edge ends inside the outermost pixel column (half covered) is complete, kept, and unbiased.
TEST(DotDetector, RejectsDotsClippedByTheBorder) {
  const vpImage<unsigned char> img =
      Render(200, 120, kBackground,
             {Disc({3.0, 60.0}, 6.0, kDot), Disc({100.0, 118.5}, 5.0, kDot), Disc({196.0, 30.0}, 5.0, kDot),
              Disc({100.0, 60.0}, 5.0, kDot), Disc({194.5, 80.0}, 4.5, kDot)},
             8, 1.0, 9);
  const DetectionReport r = DetectDots(img, DotDetectorOptions());
  ASSERT_EQ(r.dots.size(), 2u) << r.rejections.ToString();
  EXPECT_EQ(r.rejections[RejectReason::kBorder], 3) << r.rejections.ToString();
  EXPECT_LT(Nearest(r, {100.0, 60.0}).second, 0.05);
  // Its edge at u = 199.0, inside the last column [198.5, 199.5]: pixel 199 is half covered.
  EXPECT_LT(Nearest(r, {194.5, 80.0}).second, 0.05);
}

// D3: each planted impostor is refused under its own reason.
TEST(DotDetector, CountsSpuriousBlobsByReason) {
  std::vector<Shape> shapes = {
      Disc({40, 40}, 5.0, kDot),                   // a good dot
      Disc({100, 40}, 1.2, kDot),                  // speck: too small
      Disc({300, 250}, 50.0, kDot),                // too large
      testing::Rect(150, 100, 180, 104, kDot),     // bar 31 x 5: passes the ellipse test, elongated
      // A cross with 41 x 5 arms: the inner ellipse samples between the arms are light.
      testing::Rect(40, 218, 80, 222, kDot), testing::Rect(58, 200, 62, 217.99, kDot),
      testing::Rect(58, 222.01, 62, 240, kDot),
      // A ring: passes the ellipse test (its moment ellipse has a = sqrt(5^2 + 8^2)), fills 0.44 of it.
      testing::Ring({60, 150}, 5.0, 8.0, kDot),
      Disc({200, 40}, 5.0, 185),                   // faint: dark for T = 190 but contrast 15
  };
  DotDetectorOptions o;
  o.threshold_mode = ThresholdMode::kFixed;
  o.fixed_threshold = 190;
  const DetectionReport r = DetectDots(Render(480, 400, kBackground, shapes, 8), o);
  ASSERT_EQ(r.dots.size(), 1u) << r.rejections.ToString();
  EXPECT_NEAR(r.dots[0].centroid_px.x(), 40.0, 0.05);
  for (const RejectReason reason : {RejectReason::kTooSmall, RejectReason::kTooLarge, RejectReason::kElongated,
                                    RejectReason::kEllipseTest, RejectReason::kFillRatio, RejectReason::kLowContrast}) {
    EXPECT_EQ(r.rejections[reason], 1) << RejectReasonName(reason) << " in " << r.rejections.ToString();
  }
  EXPECT_EQ(r.rejections.Total(), 6);
  EXPECT_EQ(r.candidates, 7);
}

// D6: a dot inside a ring has the ring's centroid; with the shape checks off both pass them, and both are
// refused as duplicates.
TEST(DotDetector, NearDuplicatesAreRefused) {
  std::vector<Shape> shapes = {testing::Ring({150, 60}, 9.0, 12.0, kDot), Disc({150, 60}, 3.0, kDot),
                               Disc({250, 60}, 5.0, kDot)};
  DotDetectorOptions o;
  o.acceptance.ellipse_shape_precision = 0;
  o.acceptance.min_fill_ratio = 0;
  const DetectionReport r = DetectDots(Render(320, 120, kBackground, shapes, 8), o);
  ASSERT_EQ(r.dots.size(), 1u) << r.rejections.ToString();
  EXPECT_NEAR(r.dots[0].centroid_px.x(), 250.0, 0.05);
  EXPECT_EQ(r.rejections[RejectReason::kDuplicate], 2) << r.rejections.ToString();
  EXPECT_EQ(r.rejections.Total(), 2);
}

// D7 and bookkeeping on noise: whatever is reported is finite, and every candidate is accounted for.
TEST(DotDetector, NoiseImagesGiveFiniteResultsAndFullCounts) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> level(0, 255);
  for (int trial = 0; trial < 3; ++trial) {
    vpImage<unsigned char> img(120, 160);
    for (unsigned v = 0; v < img.getHeight(); ++v) {
      for (unsigned u = 0; u < img.getWidth(); ++u) img[v][u] = static_cast<unsigned char>(level(rng));
    }
    const DetectionReport r = DetectDots(img, DotDetectorOptions());
    EXPECT_EQ(r.candidates, static_cast<int>(r.dots.size()) + r.rejections.Total());
    for (const DotDetection& d : r.dots) {
      EXPECT_TRUE(d.centroid_px.allFinite());
      EXPECT_TRUE(std::isfinite(d.semi_major_px) && std::isfinite(d.contrast));
    }
  }
}

}  // namespace
}  // namespace selfcal::tracking
