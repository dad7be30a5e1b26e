#include "detection/detect_points.h"

#include <cmath>
#include <set>
#include <sstream>

#include "detection/circle_grid.h"

namespace selfcal::detection {

namespace {

ImagePoints GridPoints(const tracking::DetectionReport& det, const DetectionOptions& options) {
  tracking::GridIdentityOptions go = options.grid;
  go.rows = options.rows;
  go.cols = options.cols;
  const tracking::GridIdentityReport r = tracking::IdentifyGrid(det.dots, go);
  ImagePoints out;
  out.candidates = static_cast<int>(det.dots.size());
  if (r.outcome != tracking::GridOutcome::kSuccess) {
    out.message = std::string("grid not identified (") + tracking::GridOutcomeName(r.outcome) + "): " + r.message;
    if (r.outcome != tracking::GridOutcome::kTooFewDots) out.message += " (" + std::to_string(det.dots.size()) + " dots detected)";
    return out;
  }
  for (const tracking::GridDot& g : r.dots) out.points_px[g.id] = g.centroid_px;
  out.ok = true;
  std::ostringstream m;
  m << r.dots.size() << " dots on the grid, origin dot " << r.origin_area_ratio << " x its neighbours' area, "
    << r.unassigned_detections << " other blobs";
  out.message = m.str();
  return out;
}

ImagePoints AprilTagPoints(const vpImage<unsigned char>& image, const tracking::DetectionReport& det,
                           const DetectionOptions& options) {
  std::vector<tracking::TagDot> layout;
  for (size_t k = 0; k < options.tag_dots_m.size(); ++k) layout.push_back({static_cast<int>(k), options.tag_dots_m[k]});
  const int per_tag = static_cast<int>(layout.size());
  const std::vector<tracking::AprilTagDetection> tags = tracking::DetectAprilTags(image, options.apriltag);
  std::map<int, std::vector<int>> ids_of_detection;  // detection index -> the ids that claim it
  std::map<int, int> detections_of_id;               // id -> how many detections it names (a reprinted tag)
  for (const tracking::AprilTagDetection& tag : tags) {
    for (const tracking::TagDotMatch& m :
         tracking::AssignDotsNearTag(tag, options.tag_side_m, layout, det.dots, options.tag_tolerance_px)) {
      if (m.detection_index < 0) continue;
      ids_of_detection[m.detection_index].push_back(tag.id * per_tag + m.id);
      ++detections_of_id[tag.id * per_tag + m.id];
    }
  }
  ImagePoints out;
  out.candidates = static_cast<int>(det.dots.size());
  for (const auto& [index, ids] : ids_of_detection) {
    if (ids.size() != 1 || detections_of_id[ids.front()] != 1) continue;  // claimed twice: nobody names it
    out.points_px[ids.front()] = det.dots[static_cast<size_t>(index)].centroid_px;
  }
  out.ok = !out.points_px.empty();
  out.message = std::to_string(tags.size()) + " AprilTags, " + std::to_string(out.points_px.size()) + " of " +
                std::to_string(det.dots.size()) + " dots named";
  if (tags.empty()) out.message = "no AprilTag found (" + std::to_string(det.dots.size()) + " dots detected)";
  return out;
}

ImagePoints OrderPoints(const tracking::DetectionReport& all, const DetectionOptions& options) {
  const FilteredDots f = FilterTexture(all, options.blob_filter);
  const tracking::DetectionReport& det = f.report;
  ImagePoints out;
  out.candidates = static_cast<int>(all.dots.size());
  for (size_t k = 0; k < det.dots.size(); ++k) out.points_px[static_cast<int>(k)] = det.dots[k].centroid_px;
  out.ok = !out.points_px.empty();
  out.message = out.ok ? std::to_string(det.dots.size()) + " dots in raster order" : "no dot detected";
  if (f.texture_blobs > 0) out.message += " (" + std::to_string(f.texture_blobs) + " blobs unlike the others left out)";
  return out;
}

ImagePoints CirclePoints(const tracking::DetectionReport& all, const DetectionOptions& options) {
  const FilteredDots f = FilterTexture(all, options.blob_filter);
  const CircleGridDetection c = FindCircleGrid(f.report.dots, CircleGridLayout{options.rows, options.cols, options.asymmetric});
  ImagePoints out;
  out.candidates = static_cast<int>(all.dots.size());
  out.ok = c.found;
  out.message = c.message;
  if (f.texture_blobs > 0) out.message += " (" + std::to_string(f.texture_blobs) + " blobs unlike the others left out)";
  for (size_t k = 0; k < c.centres_px.size(); ++k) out.points_px[static_cast<int>(k)] = c.centres_px[k];
  return out;
}

// The points of the dots of one polarity, and how clearly they stand out (ContrastScore of the dots used).
struct PolarPoints {
  ImagePoints points;
  double score = 0;
};

PolarPoints DotPointsOfPolarity(const vpImage<unsigned char>& image, const DetectionOptions& options, Polarity polarity) {
  const tracking::DetectionReport det = DetectDotsOfPolarity(image, options.dots, polarity);
  PolarPoints out;
  const bool filtered = options.detector == Detector::kCircles || options.identity == Identity::kOrder;
  out.score = ContrastScore(filtered ? FilterTexture(det, options.blob_filter).report.dots : det.dots);
  if (options.detector == Detector::kCircles) {
    out.points = CirclePoints(det, options);
  } else if (options.identity == Identity::kGrid) {
    out.points = GridPoints(det, options);
  } else if (options.identity == Identity::kAprilTag) {
    out.points = AprilTagPoints(image, det, options);  // the tags are read in the image as it is
  } else {
    out.points = OrderPoints(det, options);
  }
  out.points.polarity = polarity;
  return out;
}

// kAuto: the polarity whose grid is found (dots + grid, circles), else the larger score.
ImagePoints DotPoints(const vpImage<unsigned char>& image, const DetectionOptions& options) {
  if (options.polarity != Polarity::kAuto) return DotPointsOfPolarity(image, options, options.polarity).points;
  PolarPoints dark = DotPointsOfPolarity(image, options, Polarity::kDark);
  PolarPoints light = DotPointsOfPolarity(image, options, Polarity::kLight);
  const bool grid = options.detector == Detector::kCircles || options.identity == Identity::kGrid;
  const bool take_light = (grid && dark.points.ok != light.points.ok) ? light.points.ok : light.score > dark.score;
  ImagePoints out = std::move(take_light ? light.points : dark.points);
  std::ostringstream m;
  m.precision(0);
  m << std::fixed << " (polarity " << PolarityName(out.polarity) << " by auto: contrast scores dark " << dark.score
    << ", light " << light.score << ")";
  out.message += m.str();
  return out;
}

ImagePoints ChessboardPoints(const vpImage<unsigned char>& image, const DetectionOptions& options,
                             const ImagePoints* previous) {
  ChessboardOptions co = options.chessboard;
  co.rows = options.rows;
  co.cols = options.cols;
  std::vector<Eigen::Vector2d> before;
  if (previous != nullptr && previous->ok && previous->points_px.size() == static_cast<size_t>(co.rows * co.cols)) {
    for (const auto& [id, px] : previous->points_px) before.push_back(px);
  }
  const ChessboardDetection c = DetectChessboard(image, co, before);
  ImagePoints out;
  if (!c.found) {
    out.message = c.message;
    return out;
  }
  out.candidates = static_cast<int>(c.corners_px.size());
  for (size_t k = 0; k < c.corners_px.size(); ++k) out.points_px[static_cast<int>(k)] = c.corners_px[k];
  out.ok = true;
  std::ostringstream m;
  m << c.corners_px.size() << " corners, ordered by " << OrderingCueName(c.cue);
  if (c.cue == OrderingCue::kColour) m << " (squares " << c.colour_contrast << " grey levels apart)";
  out.message = m.str();
  return out;
}

ImagePoints TagCornerPoints(const vpImage<unsigned char>& image, const DetectionOptions& options) {
  const std::vector<tracking::AprilTagDetection> tags = tracking::DetectAprilTags(image, options.apriltag);
  std::map<int, int> seen;  // tag id -> how many times: a tag printed twice names no point
  for (const tracking::AprilTagDetection& tag : tags) ++seen[tag.id];
  ImagePoints out;
  out.candidates = static_cast<int>(tags.size());
  int repeated = 0;
  for (const tracking::AprilTagDetection& tag : tags) {
    if (seen[tag.id] != 1) {
      ++repeated;
      continue;
    }
    for (int k = 0; k < 4; ++k) out.points_px[TagCornerId(tag.id, k)] = tag.corners_px[static_cast<size_t>(k)];
  }
  out.ok = !out.points_px.empty();
  std::ostringstream m;
  m << tags.size() << " AprilTag" << (tags.size() == 1 ? "" : "s");
  if (!tags.empty()) {
    m << " (id";
    for (const auto& [id, count] : seen) m << " " << id;
    m << "), " << out.points_px.size() << " corners";
  }
  if (repeated > 0) m << "; " << repeated << " detections of a tag seen twice left out";
  out.message = tags.empty() ? "no AprilTag found" : m.str();
  return out;
}

ImagePoints CharucoPoints(const vpImage<unsigned char>& image, const DetectionOptions& options) {
  CharucoOptions co = options.charuco;
  co.rows = options.rows;
  co.cols = options.cols;
  const CharucoDetection c = DetectCharuco(image, co);
  ImagePoints out;
  out.ok = c.found;
  out.message = c.message;
  out.points_px = c.corners_px;
  out.candidates = c.markers;
  return out;
}

}  // namespace

const char* DetectorName(Detector detector) {
  switch (detector) {
    case Detector::kDots: return "dots";
    case Detector::kCircles: return "circles";
    case Detector::kChessboard: return "chessboard";
    case Detector::kCharuco: return "charuco";
    case Detector::kAprilTag: return "apriltag";
  }
  return "unknown";
}

const char* IdentityName(Identity identity) {
  switch (identity) {
    case Identity::kGrid: return "grid";
    case Identity::kAprilTag: return "apriltag";
    case Identity::kOrder: return "order";
  }
  return "unknown";
}

Result<Detector> ParseDetector(const std::string& name) {
  if (name == "dots") return Detector::kDots;
  if (name == "circles") return Detector::kCircles;
  if (name == "chessboard") return Detector::kChessboard;
  if (name == "charuco") return Detector::kCharuco;
  if (name == "apriltag") return Detector::kAprilTag;
  return Status::Error(ErrorCode::kInvalidInput,
                       "unknown detector `" + name + "`: dots, circles, chessboard, charuco or apriltag");
}

Result<Identity> ParseIdentity(const std::string& name) {
  if (name == "grid") return Identity::kGrid;
  if (name == "apriltag") return Identity::kAprilTag;
  if (name == "order") return Identity::kOrder;
  return Status::Error(ErrorCode::kInvalidInput, "unknown identity `" + name + "`: grid, apriltag or order");
}

Status DetectionOptions::Validate() const {
  std::ostringstream s;
  if (polarity != Polarity::kDark && detector != Detector::kDots && detector != Detector::kCircles) {
    s << "the polarity applies to the dots and circles detectors only\n";
  }
  if (asymmetric && detector != Detector::kCircles) s << "an asymmetric grid applies to the circles detector only\n";
  if (detector != Detector::kDots && identity != Identity::kGrid) {
    s << "a " << DetectorName(detector) << " board's corners are named by the board; identity " << IdentityName(identity)
      << " applies to dots only\n";
  }
  if (detector == Detector::kChessboard) {
    ChessboardOptions co = chessboard;
    co.rows = rows;
    co.cols = cols;
    if (Status v = co.Validate(); !v.ok()) s << v.message();
  } else if (detector == Detector::kAprilTag) {
    if (Status v = apriltag.Validate(); !v.ok()) s << v.message();
    if (tag_side_m < 0 || !std::isfinite(tag_side_m)) s << "apriltag detector: the tag side must be positive\n";
  } else if (detector == Detector::kCharuco) {
    CharucoOptions co = charuco;
    co.rows = rows;
    co.cols = cols;
    if (Status v = co.Validate(); !v.ok()) s << v.message();
  } else {
    if (Status v = dots.Validate(); !v.ok()) s << v.message();
    if (Status v = blob_filter.Validate(); !v.ok()) s << v.message();
    if (detector == Detector::kCircles && (rows < 2 || cols < 2)) s << "circles: a grid of at least 2 x 2 dots\n";
    if (detector == Detector::kDots && identity == Identity::kGrid) {
      tracking::GridIdentityOptions go = grid;
      go.rows = rows;
      go.cols = cols;
      if (Status v = go.Validate(); !v.ok()) s << v.message();
    }
    if (identity == Identity::kAprilTag) {
      if (Status v = apriltag.Validate(); !v.ok()) s << v.message();
      if (!(tag_side_m > 0)) s << "apriltag identity: the tag side must be positive\n";
      if (tag_dots_m.empty()) s << "apriltag identity: give the layout of the dots around every tag\n";
      if (!(tag_tolerance_px > 0)) s << "apriltag identity: the tolerance must be positive\n";
    }
  }
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

ImagePoints DetectImagePoints(const vpImage<unsigned char>& image, const DetectionOptions& options,
                              const ImagePoints* previous) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid DetectionOptions:\n" << valid.message());
  if (options.detector == Detector::kChessboard) return ChessboardPoints(image, options, previous);
  if (options.detector == Detector::kCharuco) return CharucoPoints(image, options);
  if (options.detector == Detector::kAprilTag) return TagCornerPoints(image, options);
  return DotPoints(image, options);
}

TagEdges TagEdgeDistances(const std::vector<ImagePoints>& points, double side_m) {
  std::set<int> tags;
  for (const ImagePoints& image : points) {
    for (const auto& [id, px] : image.points_px) tags.insert(id / 4);
  }
  TagEdges out;
  for (int tag : tags) {
    out.yardsticks.push_back({TagCornerId(tag, 0), TagCornerId(tag, 1), side_m});
    out.check_distances.push_back({TagCornerId(tag, 3), TagCornerId(tag, 2), side_m});
  }
  return out;
}

std::vector<ImagePoints> DetectAllImagePoints(const std::vector<const vpImage<unsigned char>*>& images,
                                              const DetectionOptions& options) {
  std::vector<ImagePoints> out;
  out.reserve(images.size());
  int last_found = -1;
  ProgressScope progress(options.progress, static_cast<int64_t>(images.size()), "detect images");
  for (const vpImage<unsigned char>* image : images) {
    out.push_back(DetectImagePoints(*image, options, last_found >= 0 ? &out[static_cast<size_t>(last_found)] : nullptr));
    if (out.back().ok) last_found = static_cast<int>(out.size()) - 1;
    progress.Advance();
  }
  return out;
}

}  // namespace selfcal::detection
