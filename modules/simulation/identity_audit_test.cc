// The identity audit against a world whose truth the test builds itself: samples named from the true
// projections (seen from the world's own camera poses, not the audit's joints -> pose path) score no
// wrong name; a swapped pair, a name moved past the gate and a dot left out are each found and counted.
#include "simulation/identity_audit.h"

#include <gtest/gtest.h>

#include "sim/image_renderer.h"
#include "support/sim_worlds.h"

namespace selfcal::simulation {
namespace {

constexpr double kOffsetPx = 0.05;  // a right name's error, well inside the 3 px gate

struct Fixture {
  sim::SimResult world;
  session::SessionLog log;
  std::vector<sim::RenderedImage> views;  // per pose, the true view
};

// A world with the rendered sessions' spacing rule, and a log accepting every pose but pose 2 whose
// samples name every dot in view at its true projection + kOffsetPx in u and v.
Fixture MakeFixture() {
  sim::SimOptions options;
  options.separation_dot_radius_m = sim::kDefaultDotRadiusM;
  Fixture f{testing::PumaArcWorld(options), {}, {}};
  EXPECT_TRUE(f.world.ok) << f.world.message;
  const sim::DotScene scene = sim::MakeDotScene(f.world.truth);
  sim::RenderOptions render;
  render.supersampling = 2;  // the truth per dot does not depend on it
  const int n = static_cast<int>(f.world.observations.poses.size());
  f.log.num_poses = n;
  f.log.accepted.resize(n);
  for (int k = 0; k < n; ++k) {
    f.views.push_back(sim::RenderDots(f.world.truth.camera_true, f.world.truth.base_from_cam[k], scene, render, 1));
    if (k == 2) continue;
    session::AcceptedSample s;
    s.pose = k;
    s.id = "p" + std::to_string(k);
    const Eigen::VectorXd& q = f.world.observations.poses[k].joints_rad;
    s.joints_rad.assign(q.data(), q.data() + q.size());
    for (const sim::RenderedDot& d : f.views[k].dots) {
      if (!(d.in_front && d.fully_inside)) continue;
      s.dots.push_back({d.id, d.projected_centre_px.x() + kOffsetPx, d.projected_centre_px.y() + kOffsetPx});
    }
    f.log.accepted[k] = s;
  }
  return f;
}

int InView(const sim::RenderedImage& view) {
  int n = 0;
  for (const sim::RenderedDot& d : view.dots) n += d.in_front && d.fully_inside ? 1 : 0;
  return n;
}

TEST(IdentityAudit, RightNamesScoreNoWrongIdentityAndEveryDotInView) {
  const Fixture f = MakeFixture();
  const IdentityAudit audit = AuditIdentities(f.world, f.log);
  EXPECT_EQ(audit.poses_planned, f.log.num_poses);
  EXPECT_EQ(audit.samples_accepted, f.log.num_poses - 1);
  EXPECT_EQ(audit.wrong_total, 0);
  EXPECT_FALSE(audit.worst.has_value());
  EXPECT_DOUBLE_EQ(audit.ratio_min, 1.0);
  // The audit's truth comes from the recorded joints; the fixture's from the world's camera poses.
  EXPECT_NEAR(audit.max_right_error_px, kOffsetPx * std::sqrt(2.0), 1e-6);
  for (const SampleIdentities& s : audit.samples) {
    EXPECT_NE(s.pose, 2);
    EXPECT_EQ(s.in_view, InView(f.views[s.pose])) << s.pose_id;
    EXPECT_EQ(s.named, s.in_view) << s.pose_id;
  }
}

TEST(IdentityAudit, FindsASwappedPairANameBeyondTheGateAndAMissingDot) {
  Fixture f = MakeFixture();
  std::vector<session::SampleDot>& dots = f.log.accepted[3]->dots;
  ASSERT_GE(dots.size(), 4u);
  const int a = dots[0].id, b = dots[1].id;
  std::swap(dots[0].id, dots[1].id);  // two wrong names: each is its neighbour's dot
  dots[2].u_px += 4.0;                // past the 3 px gate, though still nearest its own dot
  dots.erase(dots.begin() + 3);       // a dot in view left unnamed
  f.log.accepted[5]->dots[0].id = 999;  // a name no dot has
  const IdentityAudit audit = AuditIdentities(f.world, f.log);
  EXPECT_EQ(audit.wrong_total, 4);
  ASSERT_EQ(audit.wrong.size(), 4u);
  EXPECT_EQ(audit.wrong[0].pose, 3);
  EXPECT_EQ(audit.wrong[0].id, b);
  EXPECT_EQ(audit.wrong[0].true_id, a);
  EXPECT_NEAR(audit.wrong[0].true_distance_px, kOffsetPx * std::sqrt(2.0), 1e-6);
  EXPECT_GT(audit.wrong[0].own_distance_px, audit.gate_px);
  EXPECT_EQ(audit.wrong[1].id, a);
  EXPECT_EQ(audit.wrong[1].true_id, b);
  EXPECT_EQ(audit.wrong[2].true_id, audit.wrong[2].id);
  EXPECT_NEAR(audit.wrong[2].own_distance_px, std::hypot(4.0 + kOffsetPx, kOffsetPx), 1e-6);
  EXPECT_EQ(audit.wrong[3].pose, 5);
  EXPECT_FALSE(std::isfinite(audit.wrong[3].own_distance_px));
  ASSERT_TRUE(audit.worst.has_value());
  EXPECT_EQ(audit.worst->id, 999);
  for (const SampleIdentities& s : audit.samples) {
    if (s.pose != 3) continue;
    EXPECT_EQ(s.named, s.in_view - 1);
    EXPECT_EQ(s.named_in_view, s.in_view - 1);
    EXPECT_EQ(s.wrong, 3);
  }
  EXPECT_LT(audit.ratio_min, 1.0);
  EXPECT_LE(audit.named_min, InView(f.views[3]) - 1);
}

}  // namespace
}  // namespace selfcal::simulation
