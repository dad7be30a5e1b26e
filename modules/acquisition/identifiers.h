// The dot identifiers `selfcal run --identify` and `selfcal name-dots` choose from (session_runner.h,
// DotIdentifier): who names the first frame's dots, and which dots any later frame can name again.
//
//   order      DetectionOrderIdentifier (session_runner.h): 0, 1, ... in the detector's raster order.
//   grid       tracking::IdentifyGrid (grid_identity.h): id = row * cols + col on a modified circle grid;
//              any frame that shows the grid names its dots, so every grid dot lost in a move comes back.
//   apriltag   tracking::DetectAprilTags + AssignDotsNearTag (apriltag_identity.h): the same layout of dots
//              printed around every tag (positions in the tag's frame), id = tag id * layout size + k;
//              any frame that shows the tag names them again. The tag corners themselves are not dots
//              (the session tracks and records blobs), so they are not named.
//   reference  the reference dots saved in setup.json by `selfcal name-dots` (the ids the operator saw):
//              a detection is named when exactly one reference dot lies within the gate and the two are
//              each other's nearest (a detection between two references, or two detections near one, is
//              left unnamed). For the first frame only, taken where the naming frame was taken.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "acquisition/session_runner.h"
#include "session/setup_file.h"
#include "tracking/apriltag_identity.h"
#include "tracking/grid_identity.h"

namespace selfcal::acquisition {

enum class IdentifierKind { kOrder, kGrid, kAprilTag, kReference };
const char* IdentifierKindName(IdentifierKind kind);
// "order", "grid", "apriltag" or "reference"; kInvalidInput otherwise.
Result<IdentifierKind> ParseIdentifierKind(const std::string& name);

struct IdentifierOptions {
  IdentifierKind kind = IdentifierKind::kOrder;
  tracking::GridIdentityOptions grid;
  tracking::AprilTagOptions apriltag;
  double tag_side_m = 0;                    // the black border's outer side (apriltag: required)
  std::vector<Eigen::Vector2d> tag_dots_m;  // the layout around every tag, (x, y) in its frame (required)
  double tag_tolerance_px = 3.0;            // a layout dot takes the only detection this close to its prediction
  double reference_gate_px = 4.0;           // reference: the gate around each reference dot
  Status Validate() const;
};

class GridIdentifier : public DotIdentifier {
 public:
  explicit GridIdentifier(tracking::GridIdentityOptions options) : options_(std::move(options)) {}
  Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                      const tracking::DetectionReport& detections) override;
  std::vector<tracking::PreviousDot> FindMarked(const capture::Frame& frame,
                                                const tracking::DetectionReport& detections,
                                                const std::vector<int>& missing_ids) override;
  std::vector<int> MarkedIds() const override;  // every grid id

 private:
  tracking::GridIdentityOptions options_;
};

class AprilTagIdentifier : public DotIdentifier {
 public:
  explicit AprilTagIdentifier(IdentifierOptions options) : options_(std::move(options)) {}
  Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                      const tracking::DetectionReport& detections) override;
  std::vector<tracking::PreviousDot> FindMarked(const capture::Frame& frame,
                                                const tracking::DetectionReport& detections,
                                                const std::vector<int>& missing_ids) override;
  std::vector<int> MarkedIds() const override { return named_ids_; }  // the ids the first frame named

 private:
  // Every layout dot of every tag in `frame` that exactly one detection matches (a detection two layout
  // dots claim is given to neither), sorted by id.
  std::vector<tracking::PreviousDot> Name(const capture::Frame& frame,
                                          const tracking::DetectionReport& detections) const;
  IdentifierOptions options_;
  std::vector<int> named_ids_;
};

class ReferenceIdentifier : public DotIdentifier {
 public:
  ReferenceIdentifier(std::vector<session::ReferenceDot> reference, double gate_px)
      : reference_(std::move(reference)), gate_px_(gate_px) {}
  Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                      const tracking::DetectionReport& detections) override;

 private:
  std::vector<session::ReferenceDot> reference_;
  double gate_px_;
};

// The identifier of `options` (Validate()d); `reference` is used by kReference, which refuses an empty
// one (the setup has no reference dots: name them first).
Result<std::unique_ptr<DotIdentifier>> MakeDotIdentifier(const IdentifierOptions& options,
                                                         const std::vector<session::ReferenceDot>& reference);

}  // namespace selfcal::acquisition
