// Dot identities of a simulated session scored against the simulator's hidden truth (issue 12): for
// every accepted sample, which dots the camera really had in view, how many of them the session named,
// and which names are wrong.
//
// Truth per sample: the true camera pose PointsFromCam(nominal, rho_true, joints_rad) (in the points' frame:
// the flange in eye-to-hand) at the sample's
// recorded joints, the true camera (f_x, k1) and the world's dot discs (sim::MakeDotScene, as the
// simulated camera renders them). Visibility is the renderer's (sim::RenderDots): a dot is in view when
// its whole disc is in front of the camera and inside the image (RenderedDot in_front && fully_inside).
//
// A named dot (id, u, v) is wrong when its pixel is farther than gate_px from the true projection of
// dot `id` (or dot `id` is not in front of the camera), or nearer to another dot's true projection than
// to its own. The gate: a right name's pixel differs from its dot's projected centre by the centroid
// noise (0.01 px std measured at grey noise 2; 0.02 px assumed by the solvers) plus the perspective
// ellipse-centre bias (< 0.02 px for 4 mm discs at 0.65 m, sim::EllipseCentrePx) plus k1's share (of the
// same order), well under 0.1 px; two dots' projected centres are about 1.5 projected diameters or
// more apart in the planned views (the world's spacing rule: rims 0.5 of the larger diameter apart; ~16 px
// for the arc's 11 px discs). 3 px lies 30x above the first and well below half the second, and is the
// radius the simulator's own TruthIdentifier names within.
// max_right_error_px reports how far the right names really were, so that the gate can be checked.
//
// A sample whose recorded joints differ from the arm's true joints at exposure (a jog between settle
// and capture) is scored at its recorded joints: what the calibration will use.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "base/status.h"
#include "session/samples.h"
#include "sim/sim_world.h"

namespace selfcal::simulation {

struct IdentityAuditOptions {
  double gate_px = 3.0;  // see the header comment
};

struct WrongIdentity {
  int pose = -1;
  std::string pose_id;
  int id = -1;  // the name the session gave
  Eigen::Vector2d pixel_px = Eigen::Vector2d::Zero();
  // Distance to the true projection of dot `id`; infinity when that dot is behind the camera.
  double own_distance_px = std::numeric_limits<double>::infinity();
  int true_id = -1;  // the dot whose true projection is nearest to the pixel (-1: none in front)
  double true_distance_px = std::numeric_limits<double>::infinity();
};

struct SampleIdentities {
  int pose = -1;
  std::string pose_id;
  int in_view = 0;        // dots whose whole disc the true camera sees
  int named = 0;          // dots the sample names
  int named_in_view = 0;  // of those, in view
  int wrong = 0;
  double max_right_error_px = 0;  // largest distance of a right name from its dot's true projection
  // The dots in view the sample does not name, by id, at their true projected centres: where a naming
  // that missed them should have looked.
  std::vector<std::pair<int, Eigen::Vector2d>> missed;
  double ratio() const { return in_view > 0 ? static_cast<double>(named_in_view) / in_view : 0.0; }
};

struct IdentityAudit {
  CameraMount configuration = CameraMount::kEyeInHand;  // the world's (its nominal robot's mount)
  double gate_px = 0;
  int poses_planned = 0;
  int samples_accepted = 0;
  std::vector<SampleIdentities> samples;  // accepted samples in plan order
  // Over the accepted samples (0 when there is none).
  double named_mean = 0, in_view_mean = 0, ratio_mean = 0, ratio_min = 0;
  int named_min = 0, in_view_min = 0;
  int wrong_total = 0;
  double max_right_error_px = 0;
  std::optional<WrongIdentity> worst;  // the wrong name farthest from its own dot
  std::vector<WrongIdentity> wrong;    // every wrong name, in plan order
};

// Scores the accepted samples of `log` against the truth of `world` (the world the session ran in).
IdentityAudit AuditIdentities(const sim::SimResult& world, const session::SessionLog& log,
                              const IdentityAuditOptions& options = IdentityAuditOptions());

// The audit as JSON (pixels in px; "wrong" lists at most 50 cases, "wrong_total" counts them all).
nlohmann::json IdentityAuditJson(const IdentityAudit& audit);

// One line: "<accepted>/<planned> samples accepted; named per sample mean M, min m of in view mean V
// (ratio mean R %, min r %); W wrong identities (gate G px; right names within E px)".
std::string IdentityAuditSummary(const IdentityAudit& audit);

}  // namespace selfcal::simulation
