#include "acquisition/identifiers.h"

#include <algorithm>
#include <limits>
#include <map>

namespace selfcal::acquisition {

namespace {

std::vector<tracking::PreviousDot> OnlyIds(std::vector<tracking::PreviousDot> dots, const std::vector<int>& ids) {
  dots.erase(std::remove_if(
                 dots.begin(), dots.end(),
                 [&](const tracking::PreviousDot& d) { return std::find(ids.begin(), ids.end(), d.id) == ids.end(); }),
             dots.end());
  return dots;
}

// The index of the point of `points` nearest to `p`, and its distance (-1, inf for none).
template <typename Points, typename Position>
std::pair<int, double> Nearest(const Eigen::Vector2d& p, const Points& points, Position position) {
  std::pair<int, double> best{-1, std::numeric_limits<double>::infinity()};
  for (size_t k = 0; k < points.size(); ++k) {
    const double d = (position(points[k]) - p).norm();
    if (d < best.second) best = {static_cast<int>(k), d};
  }
  return best;
}

}  // namespace

const char* IdentifierKindName(IdentifierKind kind) {
  switch (kind) {
    case IdentifierKind::kOrder:
      return "order";
    case IdentifierKind::kGrid:
      return "grid";
    case IdentifierKind::kAprilTag:
      return "apriltag";
    case IdentifierKind::kReference:
      return "reference";
  }
  return "unknown";
}

Result<IdentifierKind> ParseIdentifierKind(const std::string& name) {
  for (IdentifierKind k :
       {IdentifierKind::kOrder, IdentifierKind::kGrid, IdentifierKind::kAprilTag, IdentifierKind::kReference}) {
    if (name == IdentifierKindName(k)) return k;
  }
  return Status::Error(ErrorCode::kInvalidInput,
                       "identifier '" + name + "': must be order, grid, apriltag or reference");
}

Status IdentifierOptions::Validate() const {
  switch (kind) {
    case IdentifierKind::kOrder:
      return Status::Ok();
    case IdentifierKind::kGrid:
      return grid.Validate();
    case IdentifierKind::kAprilTag:
      if (Status s = apriltag.Validate(); !s.ok()) return s;
      if (!(tag_side_m > 0) || tag_dots_m.empty() || !(tag_tolerance_px > 0)) {
        return Status::Error(ErrorCode::kInvalidInput,
                             "apriltag identifier: needs a positive tag side, at least one layout dot and a "
                             "positive tolerance");
      }
      return Status::Ok();
    case IdentifierKind::kReference:
      if (!(reference_gate_px > 0)) {
        return Status::Error(ErrorCode::kInvalidInput, "reference identifier: the gate must be positive");
      }
      return Status::Ok();
  }
  return Status::Error(ErrorCode::kInternal, "unknown identifier kind");
}

// --- grid -------------------------------------------------------------------------------------------

Result<std::vector<tracking::PreviousDot>> GridIdentifier::Identify(const capture::Frame& /*frame*/,
                                                                    const tracking::DetectionReport& detections) {
  const tracking::GridIdentityReport grid = tracking::IdentifyGrid(detections.dots, options_);
  if (grid.outcome != tracking::GridOutcome::kSuccess) {
    return Status::Error(ErrorCode::kDegenerateData, std::string("grid identity: ") +
                                                         tracking::GridOutcomeName(grid.outcome) + ": " + grid.message);
  }
  std::vector<tracking::PreviousDot> named;
  for (const tracking::GridDot& d : grid.dots) {
    named.push_back(tracking::MakePreviousDot(d.id, detections.dots[static_cast<size_t>(d.detection_index)]));
  }
  return named;
}

std::vector<tracking::PreviousDot> GridIdentifier::FindMarked(const capture::Frame& frame,
                                                              const tracking::DetectionReport& detections,
                                                              const std::vector<int>& missing_ids) {
  // Without the origin marker the ids of a later view are only defined up to the grid's symmetry: never
  // name a dot again from them.
  if (options_.origin_marker == tracking::OriginMarker::kNone) return {};
  GridIdentifier partial(options_);
  partial.options_.require_complete = false;  // a dot lost at the image edge must not hide the others
  Result<std::vector<tracking::PreviousDot>> named = partial.Identify(frame, detections);
  if (!named.ok()) return {};
  return OnlyIds(std::move(named).value(), missing_ids);
}

std::vector<int> GridIdentifier::MarkedIds() const {
  if (options_.origin_marker == tracking::OriginMarker::kNone) return {};
  std::vector<int> ids(static_cast<size_t>(options_.rows * options_.cols));
  for (size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<int>(k);
  return ids;
}

// --- AprilTags --------------------------------------------------------------------------------------

std::vector<tracking::PreviousDot> AprilTagIdentifier::Name(const capture::Frame& frame,
                                                            const tracking::DetectionReport& detections) const {
  std::vector<tracking::TagDot> layout;
  for (size_t k = 0; k < options_.tag_dots_m.size(); ++k)
    layout.push_back({static_cast<int>(k), options_.tag_dots_m[k]});
  const int per_tag = static_cast<int>(layout.size());
  std::map<int, std::vector<int>> ids_of_detection;  // detection index -> the ids that claim it
  for (const tracking::AprilTagDetection& tag : tracking::DetectAprilTags(frame.image, options_.apriltag)) {
    for (const tracking::TagDotMatch& m :
         tracking::AssignDotsNearTag(tag, options_.tag_side_m, layout, detections.dots, options_.tag_tolerance_px)) {
      if (m.detection_index >= 0) ids_of_detection[m.detection_index].push_back(tag.id * per_tag + m.id);
    }
  }
  std::vector<tracking::PreviousDot> named;
  for (const auto& [index, ids] : ids_of_detection) {
    if (ids.size() != 1) continue;  // two tags' layouts claim one blob: neither names it
    named.push_back(tracking::MakePreviousDot(ids.front(), detections.dots[static_cast<size_t>(index)]));
  }
  std::sort(named.begin(), named.end(),
            [](const tracking::PreviousDot& a, const tracking::PreviousDot& b) { return a.id < b.id; });
  // Two tags with one id in view (a reprint) would give one id twice: drop both copies.
  std::vector<tracking::PreviousDot> unique;
  for (size_t k = 0; k < named.size(); ++k) {
    const bool repeated =
        (k > 0 && named[k - 1].id == named[k].id) || (k + 1 < named.size() && named[k + 1].id == named[k].id);
    if (!repeated) unique.push_back(named[k]);
  }
  return unique;
}

Result<std::vector<tracking::PreviousDot>> AprilTagIdentifier::Identify(const capture::Frame& frame,
                                                                        const tracking::DetectionReport& detections) {
  std::vector<tracking::PreviousDot> named = Name(frame, detections);
  if (named.empty()) {
    return Status::Error(ErrorCode::kDegenerateData,
                         "apriltag identity: no layout dot of any tag in view matched a detected dot");
  }
  named_ids_.clear();
  for (const tracking::PreviousDot& d : named) named_ids_.push_back(d.id);
  return named;
}

std::vector<tracking::PreviousDot> AprilTagIdentifier::FindMarked(const capture::Frame& frame,
                                                                  const tracking::DetectionReport& detections,
                                                                  const std::vector<int>& missing_ids) {
  return OnlyIds(Name(frame, detections), missing_ids);
}

// --- reference --------------------------------------------------------------------------------------

Result<std::vector<tracking::PreviousDot>> ReferenceIdentifier::Identify(const capture::Frame& /*frame*/,
                                                                         const tracking::DetectionReport& detections) {
  const auto ref_position = [](const session::ReferenceDot& r) { return Eigen::Vector2d(r.u_px, r.v_px); };
  const auto det_position = [](const tracking::DotDetection& d) { return d.centroid_px; };
  std::vector<tracking::PreviousDot> named;
  for (size_t k = 0; k < detections.dots.size(); ++k) {
    const Eigen::Vector2d p = detections.dots[k].centroid_px;
    int within = 0, ref = -1;
    for (size_t r = 0; r < reference_.size(); ++r) {
      if ((ref_position(reference_[r]) - p).norm() <= gate_px_) {
        ++within;
        ref = static_cast<int>(r);
      }
    }
    if (within != 1) continue;  // nothing near, or two references: ambiguous
    const std::pair<int, double> back =
        Nearest(ref_position(reference_[static_cast<size_t>(ref)]), detections.dots, det_position);
    if (back.first != static_cast<int>(k)) continue;  // another detection is nearer that reference
    named.push_back(tracking::MakePreviousDot(reference_[static_cast<size_t>(ref)].id, detections.dots[k]));
  }
  if (named.empty()) {
    return Status::Error(ErrorCode::kDegenerateData,
                         "reference identity: no detection within " + std::to_string(gate_px_) +
                             " px of exactly one of the " + std::to_string(reference_.size()) +
                             " reference dots (is the arm where the naming frame was taken?)");
  }
  return named;
}

Result<std::unique_ptr<DotIdentifier>> MakeDotIdentifier(const IdentifierOptions& options,
                                                         const std::vector<session::ReferenceDot>& reference) {
  if (Status s = options.Validate(); !s.ok()) return s;
  switch (options.kind) {
    case IdentifierKind::kOrder:
      return std::unique_ptr<DotIdentifier>(std::make_unique<DetectionOrderIdentifier>());
    case IdentifierKind::kGrid:
      return std::unique_ptr<DotIdentifier>(std::make_unique<GridIdentifier>(options.grid));
    case IdentifierKind::kAprilTag:
      return std::unique_ptr<DotIdentifier>(std::make_unique<AprilTagIdentifier>(options));
    case IdentifierKind::kReference:
      if (reference.empty()) {
        return Status::Error(ErrorCode::kInvalidInput,
                             "the reference identifier needs the setup's reference_dots: name the dots with "
                             "selfcal name-dots first");
      }
      return std::unique_ptr<DotIdentifier>(
          std::make_unique<ReferenceIdentifier>(reference, options.reference_gate_px));
  }
  return Status::Error(ErrorCode::kInternal, "unknown identifier kind");
}

}  // namespace selfcal::acquisition
