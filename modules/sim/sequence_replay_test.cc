// Recorded sequences of the simulated world, replayed through capture::RecordedSequence (the code path
// of a live camera: Open, then Grab until kSequenceEnd), checked bit for bit against a fresh render and
// against their truth files.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "capture/recorded_sequence.h"
#include "sim/render_sequence.h"
#include "sim/simulated_camera.h"
#include "support/sim_worlds.h"

namespace selfcal::sim {
namespace {

using capture::CaptureError;
using capture::CaptureErrorOf;
using capture::Frame;
using capture::RecordedSequence;

constexpr double kNoLimit = -std::numeric_limits<double>::infinity();
// truth.yaml stores pixel positions with 4 decimals and areas with 4.
constexpr double kPrintedTolPx = 0.5e-4 + 1e-9;

std::string DataFolder(const std::string& name) {
  return std::string(SELFCAL_SOURCE_DIR) + "/test/data/sequences/" + name;
}

void ExpectTruthDotsMatch(const std::vector<SequenceTruthDot>& stored, const std::vector<RenderedDot>& fresh,
                          const std::string& where) {
  ASSERT_EQ(stored.size(), fresh.size()) << where;
  for (size_t k = 0; k < stored.size(); ++k) {
    const SequenceTruthDot& s = stored[k];
    const RenderedDot& f = fresh[k];
    ASSERT_EQ(s.id, f.id) << where;
    EXPECT_LT((s.projected_centre_px - f.projected_centre_px).cwiseAbs().maxCoeff(), kPrintedTolPx)
        << where << " dot " << s.id;
    EXPECT_LT((s.area_centroid_px - f.area_centroid_px).cwiseAbs().maxCoeff(), kPrintedTolPx)
        << where << " dot " << s.id;
    EXPECT_NEAR(s.area_px2, f.area_px2, kPrintedTolPx) << where << " dot " << s.id;
    EXPECT_EQ(s.in_front, f.in_front) << where << " dot " << s.id;
    EXPECT_EQ(s.visible, f.visible) << where << " dot " << s.id;
    EXPECT_EQ(s.fully_inside, f.fully_inside) << where << " dot " << s.id;
    EXPECT_EQ(s.clipped, f.clipped) << where << " dot " << s.id;
    EXPECT_EQ(s.overlapping, f.overlapping) << where << " dot " << s.id;
    EXPECT_EQ(s.near_other, f.near_other) << where << " dot " << s.id;
  }
}

// Replays `folder` and compares with the world rebuilt from scratch.
void ReplayAgainstFreshRender(const std::string& folder, size_t expected_frames) {
  const Result<SequenceTruth> truth = ReadSequenceTruth(folder + "/" + kSequenceTruthName);
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  EXPECT_EQ(truth->world_description, "testing::PumaArcWorld(noise_px = 0, world_seed = 1, noise_seed = 1)");
  const SimResult world = testing::PumaArcWorld(0.0, 1, 1);
  ASSERT_TRUE(world.ok);
  const CameraIntrinsics& camera = world.truth.camera_true;
  // The stored camera is the world's true one (9 decimals).
  EXPECT_NEAR(truth->camera.fx_px, camera.fx_px, 1e-9);
  EXPECT_EQ(truth->camera.width_px, camera.width_px);
  EXPECT_EQ(truth->camera.k1, camera.k1);
  const DotScene scene = MakeDotScene(world.truth, truth->dot_radius_m);

  RecordedSequence sequence(folder);
  ASSERT_TRUE(sequence.Open().ok());
  ASSERT_EQ(sequence.index().frames.size(), expected_frames);
  ASSERT_EQ(truth->frames.size(), expected_frames);
  size_t n = 0;
  for (;; ++n) {
    Result<Frame> frame = sequence.Grab(kNoLimit, 1.0);
    if (!frame.ok()) {
      EXPECT_EQ(CaptureErrorOf(frame.status()), CaptureError::kSequenceEnd) << frame.status().ToString();
      break;
    }
    ASSERT_LT(n, truth->frames.size());
    const SequenceTruthFrame& t = truth->frames[n];
    const std::string where = folder + " frame " + std::to_string(n);
    // Index and truth describe the same frame.
    EXPECT_EQ(frame->source, folder + "/" + t.image) << where;
    EXPECT_EQ(frame->pose_id, t.pose_id) << where;
    EXPECT_EQ(frame->pose_id, world.observations.poses[t.pose_index].id) << where;
    EXPECT_EQ(frame->sequence, t.sequence) << where;
    EXPECT_NEAR(frame->exposure_time_s, t.exposure_time_s, 1e-9) << where;
    // Bit for bit: the committed PNG is what the renderer makes today from the same world and seed.
    const RenderedImage fresh = RenderDots(camera, world.truth.base_from_cam[t.pose_index], scene, truth->render,
                                           FrameNoiseSeed(truth->render.noise_seed, t.sequence));
    int differing = 0;
    for (unsigned k = 0; k < fresh.image.getSize(); ++k) differing += fresh.image.bitmap[k] != frame->image.bitmap[k];
    EXPECT_EQ(differing, 0) << where << ": pixels differ from a fresh render (renderer or toolchain changed? "
                            << "regenerate with test/tools/selfcal_render_sequence)";
    ExpectTruthDotsMatch(t.dots, fresh.dots, where);
  }
  EXPECT_EQ(n, expected_frames);
}

TEST(SequenceReplay, CleanPumaArcSequenceIsReproducedBitForBit) {
  ReplayAgainstFreshRender(DataFolder("puma_arc_clean"), 6);
}

TEST(SequenceReplay, NoisyBlurredPumaArcSequenceIsReproducedBitForBit) {
  ReplayAgainstFreshRender(DataFolder("puma_arc_noisy"), 3);
}

TEST(SequenceReplay, CommittedSequencesStaySmall) {
  size_t total = 0;
  for (const char* name : {"puma_arc_clean", "puma_arc_noisy"}) {
    const Result<capture::SequenceIndex> index = capture::ReadSequenceIndex(DataFolder(name));
    ASSERT_TRUE(index.ok()) << index.status().ToString();
    for (const capture::SequenceEntry& e : index->frames) {
      ASSERT_TRUE(e.crc32.has_value()) << e.image;  // committed data carries checksums
      total += static_cast<size_t>(e.size_bytes);
    }
  }
  EXPECT_LT(total, 2u << 20);
}

TEST(SequenceReplay, RenderedFolderRoundTripsWithItsTruth) {
  const SimResult world = testing::PumaArcWorld(0.0, 1, 1);
  ASSERT_TRUE(world.ok);
  capture::testing::TempDir dir;
  SequenceRenderOptions options;
  options.world_description = "round trip";
  options.pose_indices = {3, 7};
  options.render.noise_std_grey = 1.5;
  options.render.noise_seed = 99;
  options.png_compression = 1;
  SequenceTruth written;
  const std::string folder = dir.File("seq");
  ASSERT_TRUE(RenderSequenceFolder(world, options, folder, &written).ok());
  // A second rendering into the same folder is refused: recordings are never overwritten.
  EXPECT_FALSE(RenderSequenceFolder(world, options, folder).ok());

  const Result<SequenceTruth> read = ReadSequenceTruth(folder + "/" + kSequenceTruthName);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->frames.size(), 2u);
  EXPECT_EQ(read->render.noise_seed, 99u);
  EXPECT_EQ(read->world_description, "round trip");
  // Each frame is exposed settle_s after the camera's arrival at its pose, on the frame grid.
  for (size_t n = 0; n < 2; ++n) {
    const SequenceTruthFrame& f = read->frames[n];
    const double arrival = options.first_pose_time_s + n * options.pose_interval_s;
    EXPECT_GE(f.exposure_time_s, arrival + options.settle_s);
    EXPECT_LT(f.exposure_time_s, arrival + options.settle_s + options.frame_period_s);
    EXPECT_EQ(f.pose_index, options.pose_indices[n]);
    EXPECT_EQ(f.dots.size(), 80u);
    for (size_t k = 0; k < f.dots.size(); ++k) {
      EXPECT_LT((f.dots[k].area_centroid_px - written.frames[n].dots[k].area_centroid_px).cwiseAbs().maxCoeff(),
                kPrintedTolPx);
    }
  }
  // The replayed images are the ones SimulatedCamera produced.
  RecordedSequence sequence(folder);
  ASSERT_TRUE(sequence.Open().ok());
  for (size_t n = 0; n < 2; ++n) {
    Result<Frame> frame = sequence.Grab(kNoLimit, 0);
    ASSERT_TRUE(frame.ok());
    const RenderedImage fresh = RenderDots(world.truth.camera_true, world.truth.base_from_cam[options.pose_indices[n]],
                                           MakeDotScene(world.truth), options.render,
                                           FrameNoiseSeed(options.render.noise_seed, frame->sequence));
    EXPECT_TRUE(capture::testing::SameImage(fresh.image, frame->image)) << "frame " << n;
  }
  EXPECT_EQ(CaptureErrorOf(sequence.Grab(kNoLimit, 0).status()), CaptureError::kSequenceEnd);

  const Result<SequenceTruth> missing = ReadSequenceTruth(dir.File("nothing.yaml"));
  EXPECT_FALSE(missing.ok());
  EXPECT_TRUE(missing.status().message().find("nothing.yaml") != std::string::npos);
}

}  // namespace
}  // namespace selfcal::sim
