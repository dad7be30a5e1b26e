#include "detection/contact_sheet.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace selfcal::detection {
namespace {

cv::Mat Decode(const std::string& png) {
  const std::vector<unsigned char> bytes(png.begin(), png.end());
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

// The sheet's layout (header 22 px; per tile a 22 px title, the scaled image, 6 px gaps) and its marks:
// the image itself where nothing is drawn, the red ring of point 0 where it was drawn, a red title for a
// failed image.
TEST(ContactSheet, ThumbnailsMarksAndTitles) {
  vpImage<unsigned char> a(480, 640, 128), b(480, 640, 90);
  ImagePoints pa;
  pa.ok = true;
  pa.points_px = {{0, {200.0, 100.0}}, {1, {260.0, 100.0}}, {9, {200.0, 160.0}}};
  ImagePoints pb;
  pb.message = "grid not identified";
  ContactSheetOptions o;
  o.max_tile_width_px = 320;  // half size
  o.columns = 2;
  o.grid_cols = 9;
  const Result<std::string> png = ContactSheetPng({{"a.png", &a, &pa}, {"b.png", &b, &pb}}, o);
  ASSERT_TRUE(png.ok()) << png.status().message();
  const cv::Mat sheet = Decode(*png);
  ASSERT_FALSE(sheet.empty());
  EXPECT_EQ(sheet.cols, 2 * (320 + 6) + 6 < 600 ? 600 : 2 * (320 + 6) + 6);
  EXPECT_EQ(sheet.rows, 22 + (240 + 22 + 6) + 6);
  const int tile_a_x = 6, tile_y = 22 + 22, tile_b_x = 6 + 326;
  // Untouched image pixels, scaled: the grey level on all three channels.
  const cv::Vec3b plain_a = sheet.at<cv::Vec3b>(tile_y + 200, tile_a_x + 300);
  EXPECT_EQ(plain_a, cv::Vec3b(128, 128, 128));
  const cv::Vec3b plain_b = sheet.at<cv::Vec3b>(tile_y + 120, tile_b_x + 160);
  EXPECT_EQ(plain_b, cv::Vec3b(90, 90, 90));
  // Point 0 at (200, 100) is at (99.75, 49.75) on the half-size tile; its red ring has radius 7 px.
  int red = 0;
  for (int dv = -9; dv <= 9; ++dv) {
    for (int du = -9; du <= 9; ++du) {
      const cv::Vec3b p = sheet.at<cv::Vec3b>(tile_y + 50 + dv, tile_a_x + 100 + du);
      red += (p[2] > 200 && p[1] < 80 && p[0] < 80) ? 1 : 0;
    }
  }
  EXPECT_GT(red, 20);
  // The failed image's title is red, the other's green.
  int red_title = 0, green_title = 0;
  for (int v = 22; v < 44; ++v) {
    for (int u = 0; u < sheet.cols; ++u) {
      const cv::Vec3b p = sheet.at<cv::Vec3b>(v, u);
      if (u >= tile_b_x) red_title += (p[2] > 200 && p[1] < 80) ? 1 : 0;
      if (u < tile_b_x) green_title += (p[1] > 180 && p[2] < 80) ? 1 : 0;
    }
  }
  EXPECT_GT(red_title, 10);
  EXPECT_GT(green_title, 10);
}

// Red pixels (the failed label's and the reason's text) in the rows [v0, v1) of the tile at x0 of width w.
int RedPixels(const cv::Mat& sheet, int x0, int w, int v0, int v1) {
  int red = 0;
  for (int v = v0; v < v1; ++v) {
    for (int u = x0; u < x0 + w; ++u) {
      const cv::Vec3b p = sheet.at<cv::Vec3b>(v, u);
      red += (p[2] > 200 && p[1] < 80 && p[0] < 80) ? 1 : 0;
    }
  }
  return red;
}

// A failed image says why on its own tile: the label on the first line of a darkened band, then the reason
// wrapped over as many lines as it takes (here three at 320 px), the rest of the image untouched; an image
// with points has no band.
TEST(ContactSheet, AFailedTileShowsItsOutcomeAndReason) {
  vpImage<unsigned char> a(480, 640, 128), b(480, 640, 90);
  ImagePoints pa;
  pa.ok = true;
  pa.points_px = {{0, {200.0, 300.0}}};
  ImagePoints pb;
  pb.message = "too_few_dots: 72 detections, need 77; the lattice of 12 x 12 cells holds 77 dots, configured "
               "11 x 7 (white dots on a dark board?)";
  ContactSheetOptions o;
  o.max_tile_width_px = 320;
  o.columns = 2;
  o.failed_label = "SKIPPED";
  const Result<std::string> png = ContactSheetPng({{"a.png", &a, &pa}, {"b.png", &b, &pb}}, o);
  ASSERT_TRUE(png.ok()) << png.status().message();
  const cv::Mat sheet = Decode(*png);
  ASSERT_FALSE(sheet.empty());
  const int tile_y = 22 + 22, tile_a_x = 6, tile_b_x = 6 + 326;
  // Lines of 15 px from 4 px below the tile's top: the label, then the reason's lines.
  for (int line = 0; line < 4; ++line) {
    EXPECT_GT(RedPixels(sheet, tile_b_x, 320, tile_y + 4 + 15 * line, tile_y + 4 + 15 * (line + 1)), 20)
        << "line " << line;
  }
  EXPECT_EQ(RedPixels(sheet, tile_b_x, 320, tile_y + 4 + 15 * 5, tile_y + 240), 0);
  EXPECT_EQ(sheet.at<cv::Vec3b>(tile_y + 2, tile_b_x + 300), cv::Vec3b(27, 27, 27));  // 0.3 x 90: the band
  EXPECT_EQ(sheet.at<cv::Vec3b>(tile_y + 200, tile_b_x + 300), cv::Vec3b(90, 90, 90));
  EXPECT_EQ(RedPixels(sheet, tile_a_x, 320, tile_y, tile_y + 100), 0);
  EXPECT_EQ(sheet.at<cv::Vec3b>(tile_y + 2, tile_a_x + 300), cv::Vec3b(128, 128, 128));
}

TEST(ContactSheet, RefusesNoImageAndAnEmptyImage) {
  EXPECT_FALSE(ContactSheetPng({}, ContactSheetOptions()).ok());
  vpImage<unsigned char> empty;
  const Result<std::string> r = ContactSheetPng({{"e.png", &empty, nullptr}}, ContactSheetOptions());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("e.png"), std::string::npos);
}

}  // namespace
}  // namespace selfcal::detection
