#include "tracking/apriltag_identity.h"

#include <cmath>
#include <iostream>
#include <memory>

#include <gtest/gtest.h>

#include "tracking/tracking_test_util.h"

#if defined(SELFCAL_HAVE_APRILTAG_LIBRARY)
#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/tag36h11.h>
#endif

namespace selfcal::tracking {
namespace {

constexpr double kWhite = 225, kBlack = 25;

// image_from_tag: tag plane in units of the tag side (black border corners at (+-0.5, +-0.5), +y up) to
// pixels. A perspective view, rolled by roll_deg.
Eigen::Matrix3d TagView(double roll_deg, double side_px, const Eigen::Vector2d& centre) {
  const double a = roll_deg * M_PI / 180;
  Eigen::Matrix3d m;
  m << side_px * std::cos(a), side_px * std::sin(a), centre.x(),  // +y up: v decreases with y at roll 0
      side_px * std::sin(a), -side_px * std::cos(a), centre.y(),  //
      0.12, -0.08, 1.0;
  return m;
}

#if defined(SELFCAL_HAVE_APRILTAG_LIBRARY)

// The 36h11 bitmap of `id` (total_width x total_width cells: one white cell, the black border, the data),
// drawn through image_from_tag with 8 x 8 supersampling; everything outside the bitmap is white (a
// generous quiet zone). Extra shapes (dots) are drawn on top.
vpImage<unsigned char> RenderTag(int id, const Eigen::Matrix3d& image_from_tag, const std::vector<testing::Shape>& dots) {
  std::unique_ptr<apriltag_family_t, void (*)(apriltag_family_t*)> family(tag36h11_create(), tag36h11_destroy);
  std::unique_ptr<image_u8_t, void (*)(image_u8_t*)> bitmap(apriltag_to_image(family.get(), id), image_u8_destroy);
  const int total = bitmap->width;
  const int border = family->width_at_border;
  const int first = (total - border) / 2;  // the black border's first cell
  const Eigen::Matrix3d tag_from_image = image_from_tag.inverse();
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  const double half = 0.5 * total / border;  // the bitmap's extent in tag units
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(-half, -half), Eigen::Vector2d(half, -half),
                                  Eigen::Vector2d(half, half), Eigen::Vector2d(-half, half)}) {
    const Eigen::Vector2d p = (image_from_tag * c.homogeneous()).hnormalized();
    u0 = std::min(u0, p.x());
    v0 = std::min(v0, p.y());
    u1 = std::max(u1, p.x());
    v1 = std::max(v1, p.y());
  }
  testing::Shape tag{[&](double u, double v) {
                       const Eigen::Vector2d t = (tag_from_image * Eigen::Vector3d(u, v, 1)).hnormalized();
                       const int col = static_cast<int>(std::floor((t.x() + 0.5) * border)) + first;
                       const int row = static_cast<int>(std::floor((0.5 - t.y()) * border)) + first;
                       if (col < 0 || row < 0 || col >= total || row >= total) return false;
                       return bitmap->buf[row * bitmap->stride + col] < 128;
                     },
                     u0, v0, u1, v1, kBlack};
  std::vector<testing::Shape> shapes = dots;
  shapes.push_back(tag);
  return testing::Render(640, 480, kWhite, shapes, 8, 1.0, 7);
}

TEST(AprilTag, RenderedTagIdAndCorners) {
  double worst = 0;
  for (const int id : {0, 123, 586}) {
    for (const double roll : {0.0, 70.0, 235.0}) {
      const Eigen::Matrix3d view = TagView(roll, 150, {320, 240});
      const std::vector<AprilTagDetection> tags = DetectAprilTags(RenderTag(id, view, {}), AprilTagOptions());
      SCOPED_TRACE("id " + std::to_string(id) + " roll " + std::to_string(roll));
      ASSERT_EQ(tags.size(), 1u);
      EXPECT_EQ(tags[0].id, id);
      const Eigen::Vector2d unit[4] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d truth = (view * unit[k].homogeneous()).hnormalized();
        // Edge refinement on an anti-aliased, noisy (1 grey level) rendering: a few hundredths of a pixel;
        // 0.25 px is the "fraction of a pixel" the yardstick needs.
        worst = std::max(worst, (tags[0].corners_px[static_cast<size_t>(k)] - truth).norm());
        EXPECT_LT((tags[0].corners_px[static_cast<size_t>(k)] - truth).norm(), 0.25)
            << "corner " << k << " at " << tags[0].corners_px[static_cast<size_t>(k)].transpose() << ", truth "
            << truth.transpose();
      }
      const Eigen::Vector2d centre = (view * Eigen::Vector3d(0, 0, 1)).hnormalized();
      EXPECT_LT((tags[0].center_px - centre).norm(), 0.25);
    }
  }
  std::cout << "[ apriltag ] 36h11, 9 renderings: worst corner error " << worst << " px\n";
}

TEST(AprilTag, DotsAroundATagGetTheirIds) {
  const double side_m = 0.04;
  const std::vector<TagDot> layout = {{100, {0.045, 0.0}}, {101, {0.0, 0.045}}, {102, {-0.045, 0.0}},
                                      {103, {0.0, -0.045}}, {104, {0.045, 0.045}}};
  const Eigen::Matrix3d view = TagView(25.0, 120, {300, 250});
  std::vector<testing::Shape> dots;
  for (const TagDot& d : layout) dots.push_back(testing::ProjectedDisc(view, d.position_in_tag_m / side_m, 0.08, kBlack));
  const vpImage<unsigned char> img = RenderTag(42, view, dots);
  const std::vector<AprilTagDetection> tags = DetectAprilTags(img, AprilTagOptions());
  ASSERT_EQ(tags.size(), 1u);
  ASSERT_EQ(tags[0].id, 42);
  const DetectionReport det = DetectDots(img, DotDetectorOptions());
  const std::vector<TagDotMatch> m = AssignDotsNearTag(tags[0], side_m, layout, det.dots, 3.0);
  ASSERT_EQ(m.size(), layout.size());
  for (size_t k = 0; k < layout.size(); ++k) {
    ASSERT_GE(m[k].detection_index, 0) << "dot " << layout[k].id;
    const Eigen::Vector2d truth = (view * (layout[k].position_in_tag_m / side_m).homogeneous()).hnormalized();
    // The centroid of a projected disc is within a few tenths of a pixel of its projected centre here.
    EXPECT_LT((det.dots[static_cast<size_t>(m[k].detection_index)].centroid_px - truth).norm(), 0.3);
    EXPECT_EQ(m[k].id, layout[k].id);
  }
  // A layout dot where nothing was printed gets no detection.
  const std::vector<TagDotMatch> none = AssignDotsNearTag(tags[0], side_m, {{7, {-0.045, 0.045}}}, det.dots, 3.0);
  EXPECT_EQ(none[0].detection_index, -1);
}

#else

TEST(AprilTag, RenderedTagIdAndCorners) { GTEST_SKIP() << "libapriltag (tag bitmaps) not found at configure time"; }

#endif

TEST(AprilTag, BlankImageHasNoTagAndBadOptionsThrow) {
  EXPECT_TRUE(DetectAprilTags(vpImage<unsigned char>(120, 160, 200), AprilTagOptions()).empty());
  AprilTagOptions o;
  o.quad_decimate = 0.5;
  o.threads = 0;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_THROW(DetectAprilTags(vpImage<unsigned char>(120, 160, 200), o), InvalidArgument);
}

}  // namespace
}  // namespace selfcal::tracking
