// The layout symmetries of circle grids (detection/circle_grid.h) and the texture filter
// (detection/blob_candidates.h) on synthetic detections with known answers.
#include "detection/circle_grid.h"

#include <random>

#include <gtest/gtest.h>

#include "detection/blob_candidates.h"

namespace selfcal::detection {
namespace {

int Rotations(const std::vector<LayoutSymmetry>& s) {
  int n = 0;
  for (const LayoutSymmetry& x : s) n += x.rotation ? 1 : 0;
  return n;
}

TEST(CircleGridLayout, SymmetriesOfEachKindOfGrid) {
  // Symmetric, not square: identity, 180 deg and two mirrors.
  std::vector<LayoutSymmetry> s = LayoutSymmetries({7, 10, false});
  EXPECT_EQ(s.size(), 4u);
  EXPECT_EQ(Rotations(s), 2);
  // Square: the 8 of the square.
  s = LayoutSymmetries({6, 6, false});
  EXPECT_EQ(s.size(), 8u);
  EXPECT_EQ(Rotations(s), 4);
  // Asymmetric with an odd number of rows (OpenCV's 4 x 11, the 7 x 11 board): a mirror across the rows
  // only, so handedness alone names it.
  s = LayoutSymmetries({11, 7, true});
  EXPECT_EQ(s.size(), 2u);
  EXPECT_EQ(Rotations(s), 1);
  // Asymmetric with an even number of rows: 180 deg only.
  s = LayoutSymmetries({10, 7, true});
  EXPECT_EQ(s.size(), 2u);
  EXPECT_EQ(Rotations(s), 2);
  // The 180 deg turn of a symmetric grid maps id 0 to the last id.
  s = LayoutSymmetries({7, 10, false});
  for (const LayoutSymmetry& x : s) {
    if (x.rotation && x.angle_rad > 1) {
      EXPECT_EQ(x.perm[0], 69);
    }
  }
}

tracking::DotDetection Blob(double area, double contrast) {
  tracking::DotDetection d;
  d.area_px2 = area;
  d.contrast = contrast;
  return d;
}

// 40 dots of one size and contrast (within the perspective's spread) among 120 texture blobs of every size
// and contrast: the dots are kept, and at most a quarter of the texture (the blobs that happen to look like
// the dots: 24 of 120 here), although the texture is the majority.
TEST(BlobFilter, KeepsTheTargetsDotsAmongAMajorityOfTexture) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<tracking::DotDetection> blobs;
  for (int k = 0; k < 40; ++k) blobs.push_back(Blob(200 * (0.8 + 0.4 * u(rng)), 150 * (0.9 + 0.2 * u(rng))));
  for (int k = 0; k < 120; ++k) blobs.push_back(Blob(std::exp(std::log(12) + u(rng) * std::log(5000 / 12.0)), 25 + 200 * u(rng)));
  const std::vector<size_t> kept = ConsistentBlobs(blobs, BlobFilterOptions());
  size_t dots = 0, texture = 0;
  for (size_t k : kept) (k < 40 ? dots : texture)++;
  EXPECT_EQ(dots, 40u);
  EXPECT_LE(texture, 30u);
  // Disabled, or too few blobs: every blob.
  BlobFilterOptions off;
  off.enabled = false;
  EXPECT_EQ(ConsistentBlobs(blobs, off).size(), blobs.size());
  EXPECT_EQ(ConsistentBlobs({blobs[0], blobs[50]}, BlobFilterOptions()).size(), 2u);
}

TEST(Polarity, NamesParseAndInvertedImagesGiveTheSameCentroids) {
  EXPECT_EQ(*ParsePolarity("light"), Polarity::kLight);
  EXPECT_FALSE(ParsePolarity("white").ok());
  // A light disc on a dark ground and its inversion: the same centroid in both polarities.
  vpImage<unsigned char> light(60, 60, 20), dark(60, 60, 235);
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 60; ++u) {
      const double r = std::hypot(u - 30.3, v - 28.6);
      const double cover = std::clamp(6.5 - r, 0.0, 1.0);
      light[v][u] = static_cast<unsigned char>(std::lround(20 + 210 * cover));
      dark[v][u] = static_cast<unsigned char>(255 - light[v][u]);
    }
  }
  const tracking::DetectionReport a = DetectDotsOfPolarity(light, tracking::DotDetectorOptions(), Polarity::kLight);
  const tracking::DetectionReport b = DetectDotsOfPolarity(dark, tracking::DotDetectorOptions(), Polarity::kDark);
  ASSERT_EQ(a.dots.size(), 1u);
  ASSERT_EQ(b.dots.size(), 1u);
  EXPECT_EQ(a.dots[0].centroid_px, b.dots[0].centroid_px);
  EXPECT_NEAR(a.dots[0].centroid_px.x(), 30.3, 0.05);
  EXPECT_NEAR(a.dots[0].centroid_px.y(), 28.6, 0.05);
  EXPECT_TRUE(DetectDotsOfPolarity(light, tracking::DotDetectorOptions(), Polarity::kDark).dots.empty());
}

}  // namespace
}  // namespace selfcal::detection
