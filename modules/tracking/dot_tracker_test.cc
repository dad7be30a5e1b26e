#include "tracking/dot_tracker.h"

#include <cmath>
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
constexpr double kNoise = 1.0;  // grey levels
constexpr int kCols = 16, kRows = 12;
constexpr double kSpacing = 25, kRadius = 4;

// A 16 x 12 lattice of discs, spacing 25 px (the tracker's window search, 5 x the dot size, reaches the
// neighbours: the hard case for identity).
std::vector<Eigen::Vector2d> Lattice() {
  std::vector<Eigen::Vector2d> c;
  for (int r = 0; r < kRows; ++r) {
    for (int k = 0; k < kCols; ++k) c.emplace_back(60.0 + kSpacing * k + 0.31 * r, 50.0 + kSpacing * r - 0.17 * k);
  }
  return c;
}

// The small motion between the two frames: rotation 0.4 deg about (320, 240), scale 1.003, shift (1.3, -0.7).
Eigen::Vector2d Move(const Eigen::Vector2d& p) {
  const double a = 0.4 * M_PI / 180, s = 1.003;
  const Eigen::Vector2d c(320, 240);
  const Eigen::Vector2d d = p - c;
  return c + s * Eigen::Vector2d(std::cos(a) * d.x() - std::sin(a) * d.y(), std::sin(a) * d.x() + std::cos(a) * d.y()) +
         Eigen::Vector2d(1.3, -0.7);
}

vpImage<unsigned char> Frame(const std::vector<Eigen::Vector2d>& centres, const std::vector<double>& radii,
                             std::uint64_t seed) {
  std::vector<Shape> shapes;
  for (size_t k = 0; k < centres.size(); ++k) {
    if (radii[k] > 0) shapes.push_back(Disc(centres[k], radii[k], kDot));
  }
  return Render(640, 480, kBackground, shapes, 8, kNoise, seed);
}

// Frame A detected, ids = lattice index of the nearest true centre.
std::vector<PreviousDot> FirstFrameDots(const std::vector<Eigen::Vector2d>& truth) {
  const DetectionReport r = DetectDots(Frame(truth, std::vector<double>(truth.size(), kRadius), 1), DotDetectorOptions());
  EXPECT_EQ(r.dots.size(), truth.size());
  std::vector<PreviousDot> prev;
  for (const DotDetection& d : r.dots) {
    int best = 0;
    for (size_t k = 1; k < truth.size(); ++k) {
      if ((truth[k] - d.centroid_px).norm() < (truth[static_cast<size_t>(best)] - d.centroid_px).norm()) {
        best = static_cast<int>(k);
      }
    }
    prev.push_back(MakePreviousDot(best, d));
  }
  return prev;
}

const TrackedDot& ById(const TrackReport& r, int id) {
  for (const TrackedDot& t : r.dots) {
    if (t.id == id) return t;
  }
  throw std::runtime_error("no id " + std::to_string(id));
}

struct Scene {
  std::vector<Eigen::Vector2d> truth = Lattice();
  std::vector<Eigen::Vector2d> next;
  std::vector<double> radii;
  Scene() {
    for (const auto& p : truth) next.push_back(Move(p));
    radii.assign(truth.size(), kRadius);
  }
};

// Expects every id but `except` tracked, within the noise of its true position.
void ExpectOthersTracked(const TrackReport& r, const Scene& s, const std::vector<int>& except) {
  for (const TrackedDot& t : r.dots) {
    if (std::find(except.begin(), except.end(), t.id) != except.end()) continue;
    EXPECT_EQ(t.status, TrackStatus::kTracked) << "id " << t.id << ": " << t.detail;
    // Noise 1 grey level on 4 px discs: ~0.01 px (dot_detector_test); 0.05 px leaves room.
    EXPECT_LT((t.centroid_px - s.next[static_cast<size_t>(t.id)]).norm(), 0.05) << "id " << t.id;
  }
}

TEST(DotTracker, ValidateAndCallerErrors) {
  DotTrackerOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.max_area_ratio = 0.5;
  o.min_dots_for_consistency = 2;
  o.consistency.iterations = 0;
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  for (const char* key : {"max_area_ratio", "min_dots_for_consistency", "iterations"}) {
    EXPECT_NE(s.message().find(key), std::string::npos) << key;
  }
  const vpImage<unsigned char> img(100, 100, 200);
  PreviousDot p;
  p.id = 1;
  p.centroid_px = {50, 50};
  p.area_px2 = 50;
  p.width_px = p.height_px = 8;
  EXPECT_THROW(TrackDots(img, {p, p}, DotTrackerOptions()), InvalidArgument);  // duplicate id
  PreviousDot bad = p;
  bad.centroid_px.x() = std::nan("");
  EXPECT_THROW(TrackDots(img, {bad}, DotTrackerOptions()), InvalidArgument);  // D7
}

TEST(DotTracker, TracksSmallMotionToTheNoise) {
  const Scene s;
  const std::vector<PreviousDot> prev = FirstFrameDots(s.truth);
  const TrackReport r = TrackDots(Frame(s.next, s.radii, 2), prev, DotTrackerOptions());
  ASSERT_EQ(r.dots.size(), prev.size());
  EXPECT_EQ(r.Count(TrackStatus::kTracked), static_cast<int>(prev.size())) << r.Summary();
  EXPECT_TRUE(r.consistency_checked) << r.consistency_message;
  EXPECT_EQ(r.IdentityFlags(), 0);
  ExpectOthersTracked(r, s, {});
  for (size_t k = 0; k < prev.size(); ++k) {
    EXPECT_EQ(r.dots[k].id, prev[k].id);                  // same order as the input
    EXPECT_LT(r.dots[k].consistency_residual_px, 0.1);    // a homography explains this motion exactly
  }
}

// D1: a vanished dot never keeps its previous centroid. The corner dot has no other dot in the region
// vpDot2 may search: lost. Dot 5 sits inside a row: vpDot2's window search (5 x its size, +-22 px) reaches
// the rim of a neighbour 25 px away and returns the part of it inside the window, which fails the area check
// (kRejected); the neighbour itself is unaffected.
TEST(DotTracker, VanishedDotHasNoCentroid) {
  Scene s;
  s.radii[0] = 0;
  s.radii[5] = 0;
  const std::vector<PreviousDot> prev = FirstFrameDots(s.truth);
  const TrackReport r = TrackDots(Frame(s.next, s.radii, 3), prev, DotTrackerOptions());
  const TrackedDot& lost = ById(r, 0);
  EXPECT_EQ(lost.status, TrackStatus::kLost) << lost.detail;
  EXPECT_FALSE(lost.centroid_px.allFinite());
  const TrackedDot& five = ById(r, 5);
  EXPECT_NE(five.status, TrackStatus::kTracked) << five.detail;
  EXPECT_FALSE(five.centroid_px.allFinite());
  EXPECT_EQ(r.Count(TrackStatus::kTracked), static_cast<int>(prev.size()) - 2) << r.Summary();
  ExpectOthersTracked(r, s, {0, 5});
}

// D2: a dot pushed against the image edge is reported as such, without a centroid.
TEST(DotTracker, DotAtTheBorder) {
  Scene s;
  // Dot 0 starts near the edge and moves 5 px left: its disc then reaches u = -1.5, past the edge.
  s.truth[0] = {7.5, 50.0};
  s.next[0] = {2.5, 49.5};
  const std::vector<PreviousDot> prev = FirstFrameDots(s.truth);
  const TrackReport r = TrackDots(Frame(s.next, s.radii, 4), prev, DotTrackerOptions());
  const TrackedDot& t = ById(r, 0);
  EXPECT_EQ(t.status, TrackStatus::kBorder) << t.detail;
  EXPECT_FALSE(t.centroid_px.allFinite());
  EXPECT_EQ(r.rejections[RejectReason::kBorder], 1);
  ExpectOthersTracked(r, s, {0});
}

// D4: an area jump, two dots fused into one blob, and two neighbours that exchanged places.
TEST(DotTracker, IdentityChecks) {
  Scene s;
  s.radii[20] = 1.5 * kRadius;  // area x 2.25
  // 40 and 41 move 9 px towards each other and overlap (centres 7 px apart): one blob for both.
  const Eigen::Vector2d step4041 = s.truth[41] - s.truth[40];
  s.next[40] = Move(s.truth[40] + 0.36 * step4041);
  s.next[41] = Move(s.truth[41] - 0.36 * step4041);
  // 70 and 71 pass each other: each ends 5 px from the other's previous centre and 20 px from its own,
  // and vpDot2 (window search from the previous centre, nearest blob first) swaps them.
  const Eigen::Vector2d step = s.truth[71] - s.truth[70];
  s.next[70] = Move(s.truth[70] + 0.8 * step);
  s.next[71] = Move(s.truth[71] - 0.8 * step);
  const std::vector<PreviousDot> prev = FirstFrameDots(s.truth);
  const TrackReport r = TrackDots(Frame(s.next, s.radii, 5), prev, DotTrackerOptions());

  EXPECT_EQ(ById(r, 20).status, TrackStatus::kAreaJump) << ById(r, 20).detail;
  EXPECT_EQ(ById(r, 40).status, TrackStatus::kMerged) << ById(r, 40).detail;
  EXPECT_EQ(ById(r, 41).status, TrackStatus::kMerged) << ById(r, 41).detail;
  EXPECT_EQ(ById(r, 70).status, TrackStatus::kInconsistent) << ById(r, 70).detail;
  EXPECT_EQ(ById(r, 71).status, TrackStatus::kInconsistent) << ById(r, 71).detail;
  EXPECT_GT(ById(r, 70).consistency_residual_px, 4.0);  // it landed on its neighbour, 5 px from its start
  for (const int id : {20, 40, 41, 70, 71}) EXPECT_FALSE(ById(r, id).centroid_px.allFinite()) << id;
  EXPECT_TRUE(r.consistency_checked) << r.consistency_message;
  EXPECT_EQ(r.IdentityFlags(), 4);
  ExpectOthersTracked(r, s, {20, 40, 41, 70, 71});
}

// Too few dots for the consistency fit: the check is skipped and says so.
TEST(DotTracker, ConsistencyNeedsEnoughDots) {
  Scene s;
  std::vector<PreviousDot> prev = FirstFrameDots(s.truth);
  prev.resize(4);
  const TrackReport r = TrackDots(Frame(s.next, s.radii, 6), prev, DotTrackerOptions());
  EXPECT_EQ(r.Count(TrackStatus::kTracked), 4);
  EXPECT_FALSE(r.consistency_checked);
  EXPECT_NE(r.consistency_message.find("4 tracked dots"), std::string::npos) << r.consistency_message;
}

}  // namespace
}  // namespace selfcal::tracking
