// Module tracking (ARCHITECTURE.md): dot detection (this header; blob_trace.h reproduces vpDot2's border
// following to the bit), tracking with vpDot2 (dot_tracker.h: per-dot status, swap/merge consistency by a
// robust planar fit, D1-D8), grid identity from the larger origin dot (grid_identity.h), AprilTag 36h11 via
// ViSP (apriltag_identity.h), gated naming by predicted position with an ambiguity test and the prediction's
// robust correction (predicted_match.h). Uses base, ViSP, Eigen.
//
// Dark dots on a light background, found in one grey image with ViSP's vpDot2 (../shared/RELIABILITY.md D2, D3, D6,
// D7).
//
// Pixels: origin at the centre of the top-left pixel, u to the right, v down (as camera/camera.h); every
// length and area in this module is in pixels (suffix _px, _px2), grey levels are 0..255, angles in
// radians.
//
// How a frame is searched (DetectDots):
//   1. candidates: 8-connected components of "dark" pixels. With ThresholdMode::kLocal (the default) a pixel
//      is dark when I <= (mean of the adaptive_window_px box around it) - adaptive_offset, so that a large
//      dark region (carpet, shadow) is not one candidate and a dot on a bright paper next to it still is;
//      with kOtsu / kFixed, when I <= the frame's threshold;
//   2. each candidate is checked in this order and counted under the first reason that rejects it (D3):
//        component area (pixel count) below min_area_px2, or far above max_area_px2 -> kTooSmall / kTooLarge
//        the blob's own threshold T: kLocal, half way between the candidate's darkest pixel and the median
//        of the window three times its bounding box (background); kOtsu / kFixed, the frame's. vpDot2 is
//        seeded at the darkest pixel (initTracking, grey levels [0, T]); it fails, or traces a blob
//        without that pixel                                         -> kTrackerFailed
//        the blob (pixels <= T, 8-connected) outside [min_area_px2, max_area_px2] -> kTooSmall / kTooLarge
//        D2, clipped by the image edge: a blob pixel within border_margin_px of the edge is (nearly) fully
//        covered, (background - I) / contrast >= max_edge_coverage  -> kBorder. A dot whose outermost
//        pixels are only partly covered ends inside the image and is kept: its centroid is not biased
//        (a dot 0.1 px from the edge is common on real targets: ros-industrial image 2's origin dot)
//        non-finite centre of gravity or moments                    -> kNonFinite (D7)
//        background (median of a ring around the bounding box) minus the dot's median level below
//        min_contrast                                               -> kLowContrast
//        vpDot2's ellipsoid test: with the ellipse of the blob's second moments (semi-axes a, b, from the
//        blob's pixels, see DotDetection::n20_px2), points at ellipse_shape_precision * (a - 1, b - 1)
//        must be dark and points at (2 - ellipse_shape_precision) * (a + 1, b + 1) light, up to
//        ellipse_bad_points_fraction of the 20 samples on each      -> kEllipseTest
//        minor / major axis below min_axis_ratio                    -> kElongated
//        area / (pi a b) outside [min_fill_ratio, max_fill_ratio]   -> kFillRatio
//   3. D6: the same blob reached from two candidates is kept once (the other counted kDuplicate); distinct
//      accepted blobs closer than duplicate_distance_px are all refused (kDuplicate): such a pair cannot be
//      told apart, and correspondence is by id, never by array index.
//
// vpDot2 itself runs with its own size and ellipsoid checks switched off: the checks above reproduce them
// so that every rejection is counted with its reason (vpDot2 drops such blobs silently).
//
// Centroids: vpDot2's centre of gravity is that of the binarised blob (its border polygon), which moves
// in steps as the anti-aliased edge crosses T. With refine_centroid the reported centroid is the
// intensity-weighted one: weights (background - I)+ over the bounding box dilated by refine_margin_px,
// pixels of other dark blobs excluded, background from the ring. Measured on 1200 rendered anti-aliased
// discs of radius 3-8 px (dot_detector_test.cc, CentroidAccuracyOnAntiAliasedDiscs): RMS error 0.10 px for
// vpDot2's centre of gravity, 0.003 px weighted without noise and 0.011 px with grey noise sigma 2.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::tracking {

// Inclusive pixel bounds.
struct PixelBox {
  int u_min = 0;
  int v_min = 0;
  int u_max = -1;
  int v_max = -1;
  int width() const { return u_max - u_min + 1; }
  int height() const { return v_max - v_min + 1; }
  bool operator==(const PixelBox& o) const {
    return u_min == o.u_min && v_min == o.v_min && u_max == o.u_max && v_max == o.v_max;
  }
};

// One accepted dot.
struct DotDetection {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  // refined when `refined`, else cog_binary_px
  Eigen::Vector2d cog_binary_px = Eigen::Vector2d::Zero();  // vpDot2's centre of gravity of the blob
  bool refined = false;
  double area_px2 = 0;          // dark pixels in the blob (8-connected, I <= threshold)
  int threshold = -1;           // the grey level that binarised this blob
  double polygon_area_px2 = 0;  // vpDot2's area: the polygon through the border pixel centres
  // Normalised central second moments n_ij = mu_ij / m00 (px^2) of the blob's dark pixels (pixel
  // centres): variance along u, covariance, variance along v. Computed here in double rather than taken
  // from vpDot2::get_nij(), whose float accumulation is unreliable for small blobs far from the origin.
  double n20_px2 = 0, n11_px2 = 0, n02_px2 = 0;
  // Ellipse with those second moments: semi-axes 2 sqrt(eigenvalue) (the radius for a uniform disc) and
  // the angle of the major axis from +u towards +v (clockwise on screen), in (-pi/2, pi/2].
  double semi_major_px = 0, semi_minor_px = 0, angle_rad = 0;
  double fill_ratio = 0;        // area_px2 / (pi semi_major semi_minor): ~1 for a filled ellipse
  double background_level = 0;  // median grey level of the ring around the bounding box
  double dot_level = 0;         // median grey level of the blob's pixels
  double contrast = 0;          // background_level - dot_level
  PixelBox bbox;                // of the blob's dark pixels
};

enum class RejectReason {
  kTooSmall = 0,
  kTooLarge,
  kBorder,
  kTrackerFailed,
  kNonFinite,
  kLowContrast,
  kEllipseTest,
  kElongated,
  kFillRatio,
  kDuplicate,
  kCount  // number of reasons, not a reason
};
const char* RejectReasonName(RejectReason reason);

struct RejectionCounts {
  std::array<int, static_cast<int>(RejectReason::kCount)> by_reason{};
  int operator[](RejectReason r) const { return by_reason[static_cast<int>(r)]; }
  void Add(RejectReason r, int n = 1) { by_reason[static_cast<int>(r)] += n; }
  int Total() const;
  std::string ToString() const;  // "too_small=3 border=1" (non-zero reasons only)
};

// kLocal: a threshold per blob, half way between its darkest pixel and its surroundings (see above).
// kOtsu: one per frame, Otsu's. kFixed: one given level.
enum class ThresholdMode { kLocal, kOtsu, kFixed };

// The checks a blob must pass, shared by DetectDots and the tracker (dot_tracker.h).
struct DotAcceptanceOptions {
  double min_area_px2 = 12;
  double max_area_px2 = 5000;
  // D2: blob pixels closer than border_margin_px to an image edge must be covered by the dot less than
  // max_edge_coverage ((background - I) / contrast); else the dot is clipped. 0 refuses any blob there.
  int border_margin_px = 1;
  double max_edge_coverage = 0.8;
  double min_contrast = 25;             // grey levels, background - dot
  double ellipse_shape_precision = 0.65;  // vpDot2's default; 0 switches the ellipsoid test off
  double ellipse_bad_points_fraction = 0.2;  // of the 20 samples per ellipse (vpDot2's default is 0)
  double min_axis_ratio = 0.3;          // minor / major semi-axis
  double min_fill_ratio = 0.8;
  double max_fill_ratio = 1.2;
  int ring_gap_px = 2;                  // the background ring starts this far outside the bbox...
  int ring_width_px = 2;                // ...and is this wide
  bool refine_centroid = true;
  int refine_margin_px = 2;             // the weighted window is the bbox dilated by this

  // Every problem, one per line, in the Status message (kInvalidInput); OK when valid.
  Status Validate() const;
};

struct DotDetectorOptions {
  ThresholdMode threshold_mode = ThresholdMode::kLocal;
  int fixed_threshold = 128;            // used with kFixed: dark means I <= fixed_threshold
  int adaptive_window_px = 41;          // kLocal candidates: side of the box mean (odd, >= 3)...
  int adaptive_offset = 15;             // ...that a dark pixel is below by at least this (grey levels)
  DotAcceptanceOptions acceptance;
  double duplicate_distance_px = 3.0;   // D6

  Status Validate() const;
};

struct DetectionReport {
  std::vector<DotDetection> dots;  // in raster order of each blob's first pixel
  RejectionCounts rejections;
  int threshold = -1;              // the frame's grey level with kOtsu / kFixed; -1 with kLocal (per dot)
  int candidates = 0;              // dark components examined (accepted + rejected)
};

// Otsu's threshold of the image histogram: the level t maximising the between-class variance of
// {I <= t} and {I > t}. Returns 0..254.
int OtsuThreshold(const vpImage<unsigned char>& image);

// The frame's threshold under kOtsu or kFixed; -1 under kLocal.
int ChooseThreshold(const vpImage<unsigned char>& image, ThresholdMode mode, int fixed_threshold);

// kLocal's threshold for a blob inside `box`: half way between the darkest pixel of the box and the median
// of the box dilated by max(width, height) on every side (clipped to the image).
int LocalThreshold(const vpImage<unsigned char>& image, const PixelBox& box);

// Finds every dark dot in `image` (see the header comment). Throws InvalidArgument when the options are
// invalid or the image is empty.
DetectionReport DetectDots(const vpImage<unsigned char>& image, const DotDetectorOptions& options);

}  // namespace selfcal::tracking
