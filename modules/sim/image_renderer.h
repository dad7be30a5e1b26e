// Renders the simulated scene as the camera would see it (../shared/DESIGN.md section 6): a light background
// with dark circular dots, exactly in perspective, with the camera's radial distortion, anti-aliased by
// supersampling, optionally blurred and noisy. Per dot it returns the truth a detector is scored
// against.
//
// Geometry. Dot d is a flat disc of radius `radius_m` centred on centres_in_base[d] with unit normal
// normals_in_base[d] (MakeDotScene: each disc faces the cameras that look at it). A pixel (u, v) covers
// [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5] (camera/camera.h: pixel centres at integers). Each pixel in
// a dot's bounding box is sampled on an S x S grid (S = supersampling); every sample is back-projected
// with PixelToNormalized (which inverts k1), the ray intersected with the disc's plane, and the sample
// is dark if the intersection lies within the radius. Coverage = dark samples / S^2, counted once when
// dots overlap (a per-pixel 64-bit sample mask), grey = background - (background - dot) * coverage.
// Then a Gaussian blur (sigma px, border replicated), additive Gaussian noise (grey levels, seeded: the
// ziggurat on SplitMix64, sim/image_formation.h), rounding and clamping to [0, 255].
//
// Cost (docs/performance.md): only the samples near the rim are projected one by one. A pixel is first
// decided whole from the disc-plane points of its corners and centre; an undecided one by a
// biquadratic interpolation of |plane point - centre|^2 - r^2 through 9 of its points, with a margin
// 50 times the interpolation's error measured at 4 more; the samples within the margin are projected.
// The verdicts are those of projecting every sample. Frame-sized buffers are kept per thread.
//
// Truth per dot, in pixels:
//   projected_centre_px  Project(centre): where the disc's centre projects.
//   area_centroid_px     centroid of the region the whole disc projects to (ellipse for k1 = 0), exact:
//                        Green's theorem on the projected rim, trapezoidal rule on 256 rim points with
//                        analytic derivatives (spectrally accurate: ~1e-12 px). Occlusion and the image
//                        border are ignored. This is what an ideal blob detector measures on an
//                        unclipped, unoccluded dot; a symmetric blur leaves it unchanged.
//   sample_centroid_px   centroid of this dot's dark supersamples inside the image (what the image holds
//                        before blur and quantisation; ~1e-3 px from area_centroid_px at S = 8).
// The two centres differ by the perspective ellipse-centre bias: for a disc not parallel to the image
// plane, the centre of the projected ellipse is not the projection of the disc's centre.
// EllipseCentrePx gives it in closed form (pinhole; see there).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "sim/sim_world.h"

namespace selfcal::sim {

// 4 mm: 8 mm discs are 11-14 px across at the default arc's 0.57-0.73 m (f_x ~ 1000 px).
inline constexpr double kDefaultDotRadiusM = 0.004;

struct DotScene {
  std::vector<Eigen::Vector3d> centres_in_base;  // dot id = index
  std::vector<Eigen::Vector3d> normals_in_base;  // unit, one per dot
  double radius_m = kDefaultDotRadiusM;
  std::vector<double> radii_m;  // per dot when not empty (a grid's larger origin dot); else radius_m for all
  double RadiusOf(size_t d) const { return radii_m.empty() ? radius_m : radii_m[d]; }
};

// The scene of `truth`: every disc's normal is the normalised mean of the unit vectors from the dot to
// the camera centres of truth.base_from_cam (a dot sticker placed to face the cameras). A flat sheet
// therefore gets nearly (not exactly) parallel normals. With truth.dot_radius_scale, dot d's radius is
// radius_m times its scale (radii_m).
DotScene MakeDotScene(const SimTruth& truth, double radius_m = kDefaultDotRadiusM);

struct RenderOptions {
  int supersampling = 8;         // samples per pixel along each axis, 1..8
  double background_grey = 200;  // exposure and contrast: the levels of paper and ink
  double dot_grey = 40;
  double blur_sigma_px = 0;   // Gaussian, 0 = none (defocus, motion)
  double noise_std_grey = 0;  // additive Gaussian pixel noise, grey levels
  uint64_t noise_seed = 1;
  // Dots whose projected rims come closer than this (px) are flagged near_other: a detector may merge
  // them once blurred and thresholded.
  double merge_gap_px = 2.0;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

struct RenderedDot {
  int id = -1;
  bool in_front = false;        // the whole disc is in front of the camera (z > 0); nothing else is set otherwise
  bool visible = false;         // some of it lies inside the image
  bool fully_inside = false;    // all of it lies inside the image
  bool clipped = false;         // visible but partly outside the image
  bool overlapping = false;     // shares at least one supersample with another dot (occlusion / merge)
  bool near_other = false;      // rims closer than merge_gap_px to another dot's (includes overlapping)
  std::vector<int> neighbours;  // ids of the dots it overlaps or is near
  Eigen::Vector2d projected_centre_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d area_centroid_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d sample_centroid_px = Eigen::Vector2d::Zero();  // (0, 0) when no sample is inside the image
  double area_px2 = 0;                                           // exact projected area
  double sample_area_px2 = 0;                                    // dark samples inside the image / S^2
  double max_radius_px = 0;                                      // largest distance from area_centroid_px to the rim
  double min_radius_px = 0;  // smallest (the disc of this radius about area_centroid_px lies inside)

  // A dot whose truth a detector can be scored against: whole, alone, in the image.
  bool Clean() const { return in_front && fully_inside && !overlapping && !near_other; }
  Eigen::Vector2d bias_px() const { return area_centroid_px - projected_centre_px; }
};

struct RenderedImage {
  vpImage<unsigned char> image;
  std::vector<RenderedDot> dots;  // one per scene dot, in id order
};

// Renders the scene seen from `base_from_cam` with the (true) camera `camera`. `noise_seed` overrides
// options.noise_seed (so that consecutive frames get different noise).
RenderedImage RenderDots(const CameraIntrinsics& camera, const Rigid3& base_from_cam, const DotScene& scene,
                         const RenderOptions& options, uint64_t noise_seed);

// Names points (e.g. detected centroids) by the rendered dots of `image`: for each point, the id of the
// visible dot whose projected centre is nearest and closer than radius_px (among `ids` when not empty),
// kNoDot when there is none, kAmbiguousDot when another point names the same dot (neither keeps it).
// The simulator's stand-in for identities (simulation/rendered_observations.h, simulation/sim_session.h).
inline constexpr int kNoDot = -1;
inline constexpr int kAmbiguousDot = -2;
std::vector<int> NameByNearestDisc(const RenderedImage& image, const std::vector<Eigen::Vector2d>& points,
                                   double radius_px, const std::vector<int>& ids = {});

// Centre of the ellipse a disc projects to through the pinhole part of `camera` (k1 ignored), px.
// Closed form: with e1, e2 orthonormal in the disc's plane and H = [e1 e2 c] (c = centre_in_cam), the
// rim a^2 + b^2 = r^2 in plane coordinates is the conic Q = diag(1, 1, -r^2); its image in pixels is
// C = K^-T H^-T Q H^-1 K^-1 (K the intrinsic matrix), and the centre of a conic
// [A b; b^T c] is -A^-1 b. The offset from Project(centre) is second order in r / z, towards the
// disc's nearer edge, and zero for a disc parallel to the image plane. For a disc on the optical axis
// at depth z tilted by alpha: the rim's extreme rays along the tilt are at f r cos(alpha) / (z +- r
// sin(alpha)), so the offset is f r^2 sin(alpha) cos(alpha) / (z^2 - r^2 sin^2(alpha)) ~
// f r^2 sin(2 alpha) / (2 z^2): at most 0.019 px for r = 4 mm at z = 0.65 m, f = 1000 px.
Eigen::Vector2d EllipseCentrePx(const CameraIntrinsics& camera, const Eigen::Vector3d& centre_in_cam,
                                const Eigen::Vector3d& normal_in_cam, double radius_m);

}  // namespace selfcal::sim
