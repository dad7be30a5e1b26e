// Renders a recorded sequence of the standard simulated world (testing::PumaArcWorld: PUMA 560 on the
// shipped arc) into a new folder: PNG frames, index.yaml and truth.yaml (sim/render_sequence.h).
//
//   selfcal_render_sequence OUT_FOLDER [--poses 0,4,8] [--blur PX] [--noise GREY] [--noise-seed N]
//                                      [--world-seed N] [--radius-mm MM]
//
// The committed test data was made with:
//   selfcal_render_sequence test/data/sequences/puma_arc_clean --poses 0,4,8,12,16,20
//   selfcal_render_sequence test/data/sequences/puma_arc_noisy --poses 2,10,18 --blur 0.8 --noise 1 --noise-seed 7
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sim/render_sequence.h"
#include "support/sim_worlds.h"

int main(int argc, char** argv) {
  CLI::App app("Render a simulated dot sequence into a recorded-sequence folder");
  std::string folder;
  std::vector<int> poses;
  double blur_px = 0, noise_grey = 0, radius_mm = 1000 * selfcal::sim::kDefaultDotRadiusM;
  uint64_t noise_seed = 1, world_seed = 1;
  app.add_option("folder", folder, "new folder to create")->required();
  app.add_option("--poses", poses, "pose indices of the world to render (default: all)")->delimiter(',');
  app.add_option("--blur", blur_px, "Gaussian blur sigma, px");
  app.add_option("--noise", noise_grey, "Gaussian pixel noise std, grey levels");
  app.add_option("--noise-seed", noise_seed, "pixel noise seed");
  app.add_option("--world-seed", world_seed, "seed of the simulated world");
  app.add_option("--radius-mm", radius_mm, "dot radius, mm");
  CLI11_PARSE(app, argc, argv);

  const selfcal::sim::SimResult world = selfcal::testing::PumaArcWorld(0.0, world_seed, 1);
  if (!world.ok) {
    std::fprintf(stderr, "simulation failed: %s\n", world.message.c_str());
    return 3;
  }
  selfcal::sim::SequenceRenderOptions options;
  std::ostringstream description;
  description << "testing::PumaArcWorld(noise_px = 0, world_seed = " << world_seed << ", noise_seed = 1)";
  options.world_description = description.str();
  options.dot_radius_m = radius_mm / 1000;
  options.render.blur_sigma_px = blur_px;
  options.render.noise_std_grey = noise_grey;
  options.render.noise_seed = noise_seed;
  options.pose_indices = poses;
  const selfcal::Status status = selfcal::sim::RenderSequenceFolder(world, options, folder);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.ToString().c_str());
    return static_cast<int>(status.code());
  }
  std::printf("wrote %s\n", folder.c_str());
  return 0;
}
