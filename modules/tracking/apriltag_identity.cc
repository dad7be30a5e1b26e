#include "tracking/apriltag_identity.h"

#include <algorithm>
#include <map>
#include <sstream>

#include <visp3/core/vpImagePoint.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include "tracking/planar_fit.h"

namespace selfcal::tracking {
namespace {

vpDetectorAprilTag::vpAprilTagFamily ToVisp(AprilTagFamily family) {
  switch (family) {
    case AprilTagFamily::kTag36h11: return vpDetectorAprilTag::TAG_36h11;
    case AprilTagFamily::kTag25h9: return vpDetectorAprilTag::TAG_25h9;
    case AprilTagFamily::kTag16h5: return vpDetectorAprilTag::TAG_16h5;
  }
  return vpDetectorAprilTag::TAG_36h11;
}

// vpDetectorAprilTag's polygon is the apriltag library's p[0..3]: bottom-left, bottom-right, top-right,
// top-left of the printed tag (AprilRobotics/apriltag#21), already our order. Measured on rendered tags
// (apriltag_identity_test.cc, RenderedTagIdAndCorners).
constexpr int kFromVisp[4] = {0, 1, 2, 3};
// The apriltag library puts pixel centres at (u + 0.5, v + 0.5) (AprilRobotics/apriltag#121; measured
// here as a +0.5 px offset of every corner on rendered tags); ours are at (u, v).
constexpr double kAprilTagPixelCentre = 0.5;

}  // namespace

Status AprilTagOptions::Validate() const {
  std::ostringstream s;
  if (!(quad_decimate >= 1.0)) s << "quad_decimate must be >= 1, got " << quad_decimate << "\n";
  if (threads < 1) s << "threads must be >= 1, got " << threads << "\n";
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

std::vector<AprilTagDetection> DetectAprilTags(const vpImage<unsigned char>& image, const AprilTagOptions& options) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid AprilTagOptions:\n" << valid.message());
  SELFCAL_CHECK(image.getWidth() > 0 && image.getHeight() > 0, "empty image");
  vpDetectorAprilTag detector(ToVisp(options.family));
  detector.setAprilTagQuadDecimate(static_cast<float>(options.quad_decimate));
  detector.setAprilTagNbThreads(options.threads);
  detector.setAprilTagRefineEdges(options.refine_edges);
  std::vector<AprilTagDetection> tags;
  if (!detector.detect(image)) return tags;
  const std::vector<int> ids = detector.getTagsId();
  for (size_t i = 0; i < detector.getNbObjects() && i < ids.size(); ++i) {
    const std::vector<vpImagePoint>& polygon = detector.getPolygon(i);
    if (polygon.size() != 4) continue;
    AprilTagDetection tag;
    tag.id = ids[i];
    for (int k = 0; k < 4; ++k) {
      const vpImagePoint& p = polygon[static_cast<size_t>(kFromVisp[k])];
      tag.corners_px[static_cast<size_t>(k)] =
          Eigen::Vector2d(p.get_u() - kAprilTagPixelCentre, p.get_v() - kAprilTagPixelCentre);
    }
    const std::vector<Eigen::Vector2d> unit = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    const std::vector<Eigen::Vector2d> corners(tag.corners_px.begin(), tag.corners_px.end());
    const auto h = FitHomography(unit, corners);
    if (!h) continue;
    tag.image_from_tag = *h;
    tag.center_px = MapPoint(*h, Eigen::Vector2d::Zero());
    tags.push_back(tag);
  }
  std::sort(tags.begin(), tags.end(), [](const AprilTagDetection& a, const AprilTagDetection& b) { return a.id < b.id; });
  return tags;
}

std::vector<TagDotMatch> AssignDotsNearTag(const AprilTagDetection& tag, double tag_side_m,
                                           const std::vector<TagDot>& layout,
                                           const std::vector<DotDetection>& detections, double tolerance_px) {
  SELFCAL_CHECK(tag_side_m > 0, "tag_side_m must be > 0, got " << tag_side_m);
  SELFCAL_CHECK(tolerance_px > 0, "tolerance_px must be > 0, got " << tolerance_px);
  std::vector<TagDotMatch> matches;
  std::map<int, int> claims;  // detection -> number of layout dots taking it
  for (const TagDot& d : layout) {
    TagDotMatch m;
    m.id = d.id;
    m.predicted_px = MapPoint(tag.image_from_tag, d.position_in_tag_m / tag_side_m);
    int found = -1, count = 0;
    double best = 0;
    for (size_t k = 0; k < detections.size(); ++k) {
      const double dist = (detections[k].centroid_px - m.predicted_px).norm();
      if (dist <= tolerance_px) {
        ++count;
        found = static_cast<int>(k);
        best = dist;
      }
    }
    if (count == 1) {
      m.detection_index = found;
      m.distance_px = best;
      ++claims[found];
    }
    matches.push_back(m);
  }
  for (TagDotMatch& m : matches) {
    if (m.detection_index >= 0 && claims[m.detection_index] > 1) {
      m.detection_index = -1;
      m.distance_px = -1;
    }
  }
  return matches;
}

}  // namespace selfcal::tracking
