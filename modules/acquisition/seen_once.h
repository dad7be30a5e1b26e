// Dots seen in few samples (issue 12: "lost dots come back"): a dot lost in the first move of a plan is
// held by one sample, sometimes two or three, and naming later (late_naming.h) cannot name it elsewhere,
// since one ray fixes no point and a gate along its whole epipolar segment is too long to name. It is
// still in the other frames, among the detections no dot was given. Once every sample's camera has been
// resected on the session's points (dot_prediction.h, SampleCameras), each such detection near the
// dot's epipolar line in another sample is a hypothesis: with the dot's rays it fixes a point, and the
// point predicts where the dot lies in every further sample, with a gate as short as that point is
// certain. A hypothesis is named only when enough further samples each hold exactly one unnamed
// detection in its gate and few hold a named dot there; it then grows (its supports triangulated in,
// the gates searched again), and it must have no rival: a second hypothesis with enough support made of
// other detections names neither. A detection claimed by two dots names neither. Nothing here reads a
// file or touches a device: the session loop (session_naming.cc) gives the frames' detections and
// journals what is named (docs/session-format.md, "dots_named_later").
#pragma once

#include <vector>

#include "acquisition/dot_prediction.h"
#include "tracking/dot_detector.h"
#include "tracking/dot_tracker.h"

namespace selfcal::acquisition {

struct SeenOnceOptions {
  DotPredictionOptions prediction;  // the resection of the samples' cameras, the rays' model error
  // Dots held by at most this many samples are looked for (naming later takes those held by more).
  int max_holders = 3;
  // A hypothesis reprojects within this many pixels onto every ray it rests on.
  double ray_residual_px = 3.0;
  // A further sample supports a hypothesis with the one unnamed detection in its gate (this chi-square),
  // a gate whose std along its longest axis is at most `max_support_sigma_px`.
  double gate_chi2 = 13.8;
  double max_support_sigma_px = 2.0;
  // Supports needed beyond the hypothesis's own two samples, and at most this many rounds of growing.
  int min_support = 3;
  int grow_rounds = 3;
  // A further sample holding a named dot in the short gate gives no support; a hypothesis with more
  // such samples than its supports divided by this is another dot's point, not this one's (a named
  // dot near the gate in one sample of many is a neighbour seen close there).
  int max_contradicted_per_support = 3;
  // A detection this close to a dot its sample holds is that dot's blob (tracking/dot_detector.h).
  double duplicate_distance_px = 3.0;
  // A projection at least this far inside the image is in view.
  double in_view_margin_px = 5.0;
};

struct SeenOnceName {
  int sample = -1;            // index into the samples given
  tracking::PreviousDot dot;  // the id named and its detection
};

struct SeenOnceReport {
  std::vector<SeenOnceName> named;  // by sample, then detection order
  int looked_for = 0;               // dots held by 1..max_holders samples
  int dots_named = 0;               // of them, those named in further samples
  int rivalled = 0;                 // dots left unnamed: two supported hypotheses
  int conflicts = 0;                // dots left unnamed: a detection also claimed by another dot
};

// The dots of `samples` held by few of them, named among each sample's detections `detected[s]`.
SeenOnceReport NameSeenOnce(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                            const std::vector<tracking::DetectionReport>& detected, const SeenOnceOptions& options);

}  // namespace selfcal::acquisition
