// Naming later (issue 12: "lost dots come back", "the information is in the images"): once a session has
// its samples, every dot the run could not name in a sample's frame, while it was seen in enough other
// samples, is looked for again in that frame. Its prediction now rests on the rays of every other
// sample, not only of those that came before, and the raw predictions are corrected on the dots the
// sample already holds (tracking/predicted_match.h, FitPredictionCorrection), which are many: the gates
// are short and the naming is the gated nearest prediction with the ambiguity test of a settled pose.
// Nothing here reads a file or touches a device: the session loop (session_naming.cc) gives the frame's
// detections and journals what is named (docs/session-format.md, "dots_named_later").
#pragma once

#include <vector>

#include "acquisition/dot_prediction.h"
#include "tracking/dot_detector.h"
#include "tracking/dot_tracker.h"
#include "tracking/predicted_match.h"

namespace selfcal::acquisition {

struct LateNamingOptions {
  DotPredictionOptions prediction;
  tracking::PredictionCorrectionOptions correction;
  tracking::PredictedMatchOptions match;
  // A dot is looked for only when at least this many other samples hold it: its point then rests on
  // four rays or more, so that one poor ray cannot carry it off (a two-ray point can lie several of its
  // own sigmas away, and a wrong name given at a settled pose from such a point then looks right beside
  // two good rays: with three, PUMA D-optimal seed 16 copied one wrong name into another sample). Dots
  // seen less often still compete: a detection in their gates is named by none.
  int min_other_samples = 4;
  // A detection this close to a dot the sample already holds is that dot's blob (tracking/dot_detector.h).
  double duplicate_distance_px = 3.0;
  // The correction needs at least this many of the sample's dots predicted from the others.
  int min_anchors = 6;
};

struct LateNaming {
  std::vector<tracking::PreviousDot> named;  // new ids of the sample, in detection order
  int ambiguous = 0;                         // detections left unnamed by the ambiguity test
  bool corrected = false;                    // false: too few anchors, nothing named
};

// The std of a prediction's gate along its longest axis, in px: what decides whether the gate is short
// enough to name (DotPredictionOptions::max_gate_sigma_px).
double GateSigmaPx(const tracking::PredictedDot& gate);

// The dots of `sample` (its joints, its named dots) that can be named among `detected` (the sample's
// frame, detected again) from the predictions of `others` (the session's other accepted samples).
LateNaming NameLater(const PredictionModel& model, const std::vector<ViewedSample>& others,
                     const ViewedSample& sample, const tracking::DetectionReport& detected,
                     const LateNamingOptions& options);

}  // namespace selfcal::acquisition
