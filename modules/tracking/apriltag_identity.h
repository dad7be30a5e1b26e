// AprilTags with ViSP's vpDetectorAprilTag: tag id and the four outer corners of its black border; and ids
// for dots laid out around a tag (a tag of known side is also a yardstick).
//
// Pixels as dot_detector.h. Tag frame (as the grid target of grid_identity.h): origin at the tag centre,
// +x towards the right edge and +y towards the top edge of the tag as printed (its bitmap's first row is
// the top), +z out of the printed face; the side s is the black border's outer side, so the corners are
// at (+-s/2, +-s/2). corners_px are always in the order
//   [0] bottom-left (-s/2, -s/2), [1] bottom-right (s/2, -s/2), [2] top-right (s/2, s/2), [3] top-left (-s/2, s/2),
// whatever the tag's rotation in the image (counter-clockwise on the printed face; counter-clockwise on
// screen for a view of the front).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/status.h"
#include "tracking/dot_detector.h"

namespace selfcal::tracking {

enum class AprilTagFamily { kTag36h11, kTag25h9, kTag16h5 };

struct AprilTagOptions {
  AprilTagFamily family = AprilTagFamily::kTag36h11;
  double quad_decimate = 1.0;  // 1 finds corners at full resolution; 2 is faster and coarser
  int threads = 1;
  bool refine_edges = true;
  Status Validate() const;
};

struct AprilTagDetection {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners_px;  // bottom-left, bottom-right, top-right, top-left (see above)
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();  // the tag centre: its homography at (0, 0)
  // Homography from the tag plane in units of the side (corners at (+-0.5, +-0.5)) to pixels.
  Eigen::Matrix3d image_from_tag = Eigen::Matrix3d::Identity();
};

// All tags of the family in `image`, sorted by id. Throws InvalidArgument on invalid options or an empty
// image.
std::vector<AprilTagDetection> DetectAprilTags(const vpImage<unsigned char>& image, const AprilTagOptions& options);

// A dot printed at a known place relative to a tag.
struct TagDot {
  int id = -1;
  Eigen::Vector2d position_in_tag_m = Eigen::Vector2d::Zero();  // (x, y) in the tag frame, z = 0
};

struct TagDotMatch {
  int id = -1;
  int detection_index = -1;  // -1: no detection, or more than one, within the tolerance
  Eigen::Vector2d predicted_px = Eigen::Vector2d::Zero();
  double distance_px = -1;
};

// Predicts each layout dot through the tag's homography (side tag_side_m) and takes the only detection
// within tolerance_px; a detection claimed by two layout dots is given to neither. Same order as `layout`.
std::vector<TagDotMatch> AssignDotsNearTag(const AprilTagDetection& tag, double tag_side_m,
                                           const std::vector<TagDot>& layout,
                                           const std::vector<DotDetection>& detections, double tolerance_px);

}  // namespace selfcal::tracking
