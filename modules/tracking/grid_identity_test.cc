#include "tracking/grid_identity.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tracking/tracking_test_util.h"

namespace selfcal::tracking {
namespace {

constexpr int kRows = 7, kCols = 9;  // not square, so that rows and columns cannot be confused

// image_from_grid for a grid seen at an angle: grid units (col, row) with +row "up" on the printed target,
// rotated in the image by roll_deg, with some perspective.
Eigen::Matrix3d View(double roll_deg, double perspective = 1.0) {
  const double a = roll_deg * M_PI / 180;
  Eigen::Matrix3d flip;  // printed target seen from the front: +row goes up the screen (-v)
  flip << 1, 0, 0, 0, -1, 0, 0, 0, 1;
  Eigen::Matrix3d rot;
  rot << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  Eigen::Matrix3d scale;
  scale << 30, 0, 0, 0, 30, 0, 0, 0, 1;
  Eigen::Matrix3d persp = Eigen::Matrix3d::Identity();
  persp(2, 0) = 1.5e-4 * perspective;
  persp(2, 1) = -1.0e-4 * perspective;
  Eigen::Matrix3d centre = Eigen::Matrix3d::Identity();
  centre(0, 2) = 320;
  centre(1, 2) = 240;
  Eigen::Matrix3d to_middle = Eigen::Matrix3d::Identity();
  to_middle(0, 2) = -(kCols - 1) / 2.0;
  to_middle(1, 2) = -(kRows - 1) / 2.0;
  return centre * persp * rot * scale * flip * to_middle;
}

// Detections of an R x C modified circle grid seen through image_from_grid: centroid = projected centre,
// area = projected disc area (radius 0.2 spacing, 0.4 for the origin). Optional pixel noise.
std::vector<DotDetection> GridDetections(const Eigen::Matrix3d& image_from_grid, int rows, int cols,
                                         bool with_marker, double noise_px, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0, noise_px > 0 ? noise_px : 1);
  std::vector<DotDetection> dets;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      DotDetection d;
      const Eigen::Vector2d g(c, r);
      d.centroid_px = (image_from_grid * g.homogeneous()).hnormalized();
      if (noise_px > 0) d.centroid_px += Eigen::Vector2d(noise(*rng), noise(*rng));
      const Eigen::Vector2d du = (image_from_grid * Eigen::Vector3d(c + 0.2, r, 1)).hnormalized() - d.centroid_px;
      const Eigen::Vector2d dv = (image_from_grid * Eigen::Vector3d(c, r + 0.2, 1)).hnormalized() - d.centroid_px;
      const double radius_scale = (with_marker && r == 0 && c == 0) ? 4.0 : 1.0;  // area ratio
      d.area_px2 = M_PI * std::abs(du.x() * dv.y() - du.y() * dv.x()) * radius_scale;
      dets.push_back(d);
    }
  }
  return dets;
}

// The index of the detection at (row, col) in GridDetections' order, shuffled by `perm`.
struct Shuffled {
  std::vector<DotDetection> dets;
  std::vector<int> truth_id;  // per detection
};

Shuffled Shuffle(const std::vector<DotDetection>& dets, int cols, std::mt19937_64* rng) {
  std::vector<int> perm(dets.size());
  for (size_t k = 0; k < perm.size(); ++k) perm[k] = static_cast<int>(k);
  std::shuffle(perm.begin(), perm.end(), *rng);
  Shuffled s;
  for (const int k : perm) {
    s.dets.push_back(dets[static_cast<size_t>(k)]);
    s.truth_id.push_back(k);  // GridDetections is row-major: index = row * cols + col
  }
  (void)cols;
  return s;
}

GridIdentityOptions Options() {
  GridIdentityOptions o;
  o.rows = kRows;
  o.cols = kCols;
  return o;
}

void ExpectIdsMatchTruth(const GridIdentityReport& r, const Shuffled& s, int expected_count) {
  ASSERT_EQ(r.outcome, GridOutcome::kSuccess) << GridOutcomeName(r.outcome) << ": " << r.message;
  ASSERT_EQ(static_cast<int>(r.dots.size()), expected_count);
  for (const GridDot& g : r.dots) {
    EXPECT_EQ(g.id, s.truth_id[static_cast<size_t>(g.detection_index)]) << "row " << g.row << " col " << g.col;
    EXPECT_EQ(g.id, g.row * kCols + g.col);
  }
}

TEST(GridIdentity, ValidateNamesEveryProblem) {
  GridIdentityOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.rows = 1;
  o.match_tolerance = 0.7;
  o.max_residual_spacing = 0.6;
  o.max_runner_up_area_ratio = 5;
  o.origin_marker = OriginMarker::kNone;
  o.require_complete = false;
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  for (const char* key : {"rows", "match_tolerance", "max_runner_up_area_ratio", "partial grid", "max_residual_spacing"}) {
    EXPECT_NE(s.message().find(key), std::string::npos) << key;
  }
}

TEST(GridIdentityOriginMarker, IdsCorrectForEveryRollWithPerspectiveAndNoise) {
  std::mt19937_64 rng(21);
  for (const double roll : {0.0, 37.0, 90.0, 135.0, 180.0, 250.0, 300.0}) {
    const Shuffled s = Shuffle(GridDetections(View(roll), kRows, kCols, true, 0.3, &rng), kCols, &rng);
    const GridIdentityReport r = IdentifyGrid(s.dets, Options());
    SCOPED_TRACE("roll " + std::to_string(roll));
    ExpectIdsMatchTruth(r, s, kRows * kCols);
    EXPECT_TRUE(r.orientation_from_marker);
    EXPECT_EQ(s.truth_id[static_cast<size_t>(r.origin_detection_index)], 0);
    EXPECT_GT(r.origin_area_ratio, 3.0);  // 4, times the perspective change of scale over one cell
    EXPECT_LT(r.origin_area_ratio, 5.5);
    EXPECT_LT(r.rms_residual_px, 0.5);  // noise 0.3 px per axis
    EXPECT_EQ(r.unassigned_detections, 0);
  }
}

TEST(GridIdentityOriginMarker, RendersDetectsAndIdentifies) {
  const Eigen::Matrix3d view = View(-20.0, 2.0);
  std::vector<testing::Shape> shapes;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      shapes.push_back(testing::ProjectedDisc(view, Eigen::Vector2d(c, r), (r == 0 && c == 0) ? 0.4 : 0.2, 40));
    }
  }
  const vpImage<unsigned char> img = testing::Render(640, 480, 210, shapes, 8, 1.5, 3);
  const DetectionReport det = DetectDots(img, DotDetectorOptions());
  ASSERT_EQ(det.dots.size(), static_cast<size_t>(kRows * kCols)) << det.rejections.ToString();
  const GridIdentityReport r = IdentifyGrid(det.dots, Options());
  ASSERT_EQ(r.outcome, GridOutcome::kSuccess) << r.message;
  for (const GridDot& g : r.dots) {
    const Eigen::Vector2d truth = (view * Eigen::Vector3d(g.col, g.row, 1)).hnormalized();
    // The centroid of a projected disc is off its projected centre by a fraction of a pixel here.
    EXPECT_LT((g.centroid_px - truth).norm(), 0.3) << "row " << g.row << " col " << g.col;
  }
}

// D5/D6 refusals, each with its reason.
TEST(GridIdentityOriginMarker, RefusesWhatItCannotDecide) {
  std::mt19937_64 rng(22);
  const Eigen::Matrix3d view = View(15.0);
  const std::vector<DotDetection> good = GridDetections(view, kRows, kCols, true, 0.0, &rng);
  {
    // Seen from behind (mirrored): with R != C the handedness puts 9 dots along the rows.
    Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity();
    mirror(0, 0) = -1;
    mirror(0, 2) = 640;
    const GridIdentityReport r = IdentifyGrid(GridDetections(mirror * view, kRows, kCols, true, 0.0, &rng), Options());
    EXPECT_EQ(r.outcome, GridOutcome::kWrongSize) << r.message;
  }
  {
    const GridIdentityReport r = IdentifyGrid(GridDetections(view, kRows, kCols, false, 0.0, &rng), Options());
    EXPECT_EQ(r.outcome, GridOutcome::kNoOriginDot) << r.message;
  }
  {
    std::vector<DotDetection> two = good;
    two[30].area_px2 *= 4;
    const GridIdentityReport r = IdentifyGrid(two, Options());
    EXPECT_EQ(r.outcome, GridOutcome::kAmbiguousOrigin) << r.message;
  }
  {
    std::vector<DotDetection> inner = good;
    std::swap(inner[0].area_px2, inner[30].area_px2);  // the large dot inside the grid
    const GridIdentityReport r = IdentifyGrid(inner, Options());
    EXPECT_EQ(r.outcome, GridOutcome::kOriginNotAtCorner) << r.message;
  }
  {
    // One more row than configured.
    const GridIdentityReport r = IdentifyGrid(GridDetections(view, kRows + 1, kCols, true, 0.0, &rng), Options());
    EXPECT_EQ(r.outcome, GridOutcome::kWrongSize) << r.message;
  }
  {
    // A spurious blob 0.15 spacing from a dot: two detections within the match tolerance.
    std::vector<DotDetection> dup = good;
    DotDetection extra = dup[40];
    extra.centroid_px += 0.15 * ((view * Eigen::Vector3d(5, 4, 1)).hnormalized() - (view * Eigen::Vector3d(4, 4, 1)).hnormalized());
    dup.push_back(extra);
    const GridIdentityReport r = IdentifyGrid(dup, Options());
    EXPECT_EQ(r.outcome, GridOutcome::kAmbiguousMatch) << r.message;
  }
  {
    std::vector<DotDetection> missing = good;
    missing.erase(missing.begin() + 40);
    GridIdentityOptions o = Options();
    const GridIdentityReport r = IdentifyGrid(missing, o);
    EXPECT_EQ(r.outcome, GridOutcome::kTooFewDots) << r.message;
    missing.push_back(DotDetection());  // a far-away impostor keeps the count at R x C
    missing.back().centroid_px = {5, 5};
    missing.back().area_px2 = good[1].area_px2;
    const GridIdentityReport r2 = IdentifyGrid(missing, o);
    EXPECT_EQ(r2.outcome, GridOutcome::kIncomplete) << r2.message;
    EXPECT_EQ(r2.unassigned_detections, 1);
    // A partial grid is accepted when asked for: the 62 dots keep their ids.
    o.require_complete = false;
    const GridIdentityReport r3 = IdentifyGrid(missing, o);
    ASSERT_EQ(r3.outcome, GridOutcome::kSuccess) << r3.message;
    EXPECT_EQ(r3.dots.size(), static_cast<size_t>(kRows * kCols - 1));
    for (const GridDot& g : r3.dots) EXPECT_NE(g.id, 40);
  }
  {
    // A dot moved by 7.5 px (0.25 spacing, inside the match tolerance of 0.3): placed, then caught by the
    // residual (max 0.15 spacing here).
    std::vector<DotDetection> bent = good;
    bent[40].centroid_px += Eigen::Vector2d(7.5, 0);
    GridIdentityOptions o = Options();
    o.max_residual_spacing = 0.15;
    const GridIdentityReport r = IdentifyGrid(bent, o);
    EXPECT_EQ(r.outcome, GridOutcome::kLargeResidual) << r.message;
  }
}

// Without a marker the ids hold up to the grid's symmetry: for R != C, a rotation by 180 degrees.
TEST(GridIdentityNoMarker, IdsUpToSymmetry) {
  std::mt19937_64 rng(23);
  GridIdentityOptions o = Options();
  o.origin_marker = OriginMarker::kNone;
  for (const double roll : {10.0, 100.0, 200.0, 280.0}) {
    const Shuffled s = Shuffle(GridDetections(View(roll), kRows, kCols, false, 0.2, &rng), kCols, &rng);
    const GridIdentityReport r = IdentifyGrid(s.dets, o);
    ASSERT_EQ(r.outcome, GridOutcome::kSuccess) << r.message;
    EXPECT_FALSE(r.orientation_from_marker);
    bool same = true, rotated = true;
    for (const GridDot& g : r.dots) {
      const int t = s.truth_id[static_cast<size_t>(g.detection_index)];
      same = same && t == g.id;
      rotated = rotated && t == kRows * kCols - 1 - g.id;
    }
    EXPECT_TRUE(same || rotated) << "roll " << roll;
    // Of the two corners compatible with 7 rows x 9 columns (id 0 and its 180-degree image), the origin is
    // the one nearest the image's top-left.
    EXPECT_LE(r.dots.front().centroid_px.sum(), r.dots.back().centroid_px.sum()) << "roll " << roll;
  }
}

}  // namespace
}  // namespace selfcal::tracking
