// Observations from rendered images instead of projected points: each pose of a simulated world is
// rendered (sim/image_renderer.h: exact perspective discs, blur, grey-level noise), its dots are detected
// with the tracking module's detector (vpDot2 + refined centroid), and each detection gets the id of the
// nearest true projected centre. That association stands in for a session's identities (tracking through
// the motion, a grid or AprilTags) so that the figures measure the centroids alone; the pixels handed on
// are the detector's, never the truth's. Used by `selfcal study --rendered` for the Table 2 rows on images
// and for the centroid accuracy figure (issue 5).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "observations/observation_set.h"
#include "sim/image_renderer.h"
#include "sim/sim_world.h"
#include "tracking/dot_detector.h"

namespace selfcal::simulation {

struct RenderedObservationOptions {
  double dot_radius_m = sim::kDefaultDotRadiusM;
  sim::RenderOptions render;            // render.noise_seed is replaced per pose (see ObserveRendered)
  tracking::DotDetectorOptions detector;
  double match_radius_px = 3.0;         // a detection farther than this from every true centre is spurious
  double assumed_noise_px = 0.05;       // ObservationSet::pixel_noise_px handed to the solvers
};

// Centroid errors of the matched detections, per coordinate, px.
struct CentroidErrors {
  int expected = 0;     // dots fully inside the image and clear of others (RenderedDot::Clean), all poses
  int detected = 0;     // detections
  int matched = 0;      // detections given an id
  int missed = 0;       // clean dots without a detection
  int spurious = 0;     // detections matching no dot, or two detections for one dot (both dropped)
  // Detection centroid minus the projected disc centre (what the solvers need; includes the
  // ellipse-centre bias of perspective), and minus the exact area centroid of the rendered ellipse (the
  // detector's own error). One entry per coordinate of every matched clean dot.
  std::vector<double> vs_projected_px, vs_area_centroid_px;
  // The ellipse-centre bias itself: area centroid minus projected centre, per coordinate.
  std::vector<double> ellipse_bias_px;
  void Append(const CentroidErrors& other);
  static double Rms(const std::vector<double>& values);
};

// The world's observations re-measured from rendered images: same poses, roles, yardsticks and check
// distances, dots_px from the detector. Pose i's image uses noise seed (noise_seed, i)
// (sim::FrameNoiseSeed). Which dots a pose keeps is the detector's decision (a merged or clipped blob
// fails its checks); the truth only names them and scores them.
ObservationSet ObserveRendered(const sim::SimResult& world, const RenderedObservationOptions& options,
                               uint64_t noise_seed, CentroidErrors* errors = nullptr);

}  // namespace selfcal::simulation
