// Renders a recorded sequence of the standard simulated world (testing::PumaArcWorld: PUMA 560 on the
// shipped arc) into a new folder: PNG frames, index.yaml and truth.yaml (sim/render_sequence.h).
//
//   selfcal_render_sequence OUT_FOLDER [--poses 0,4,8] [--blur PX] [--noise GREY] [--noise-seed N]
//                                      [--world-seed N] [--radius-mm MM] [--supersampling S]
//                                      [--flat-sheet-grid ROWSxCOLS [--spacing-mm MM]] [--detect-folder]
//
// --flat-sheet-grid puts the dots on a flat modified circle grid (sim::SimOptions::sheet_grid: the larger
// origin dot that `selfcal detect --identity grid` names the dots by). --detect-folder writes every pose
// with the joint-angle poses list and the hidden truth beside the images (simulation/detect_folder.h):
// the input of `selfcal detect --poses OUT_FOLDER/poses.yaml --robot config/robots/puma560.yaml`.
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
#include "simulation/detect_folder.h"
#include "support/sim_worlds.h"

int main(int argc, char** argv) {
  CLI::App app("Render a simulated dot sequence into a recorded-sequence folder");
  std::string folder, grid;
  std::vector<int> poses;
  double blur_px = 0, noise_grey = 0, radius_mm = 1000 * selfcal::sim::kDefaultDotRadiusM, spacing_mm = 15;
  uint64_t noise_seed = 1, world_seed = 1;
  int supersampling = selfcal::sim::RenderOptions().supersampling;
  bool detect_folder = false;
  app.add_option("folder", folder, "new folder to create")->required();
  app.add_option("--poses", poses, "pose indices of the world to render (default: all)")->delimiter(',');
  app.add_option("--blur", blur_px, "Gaussian blur sigma, px");
  app.add_option("--noise", noise_grey, "Gaussian pixel noise std, grey levels");
  app.add_option("--noise-seed", noise_seed, "pixel noise seed");
  app.add_option("--world-seed", world_seed, "seed of the simulated world");
  app.add_option("--radius-mm", radius_mm, "dot radius, mm");
  app.add_option("--supersampling", supersampling, "samples per pixel side")->check(CLI::Range(1, 8));
  app.add_option("--flat-sheet-grid", grid, "ROWSxCOLS: the dots on a flat grid with a larger origin dot");
  app.add_option("--spacing-mm", spacing_mm, "--flat-sheet-grid: dot spacing, mm")->check(CLI::PositiveNumber);
  app.add_flag("--detect-folder", detect_folder, "every pose, with poses.yaml and hidden_truth.json for selfcal detect");
  CLI11_PARSE(app, argc, argv);

  selfcal::sim::SimOptions sim;
  sim.pixel_noise_px = 0.0;
  sim.world_seed = world_seed;
  sim.noise_seed = 1;
  std::ostringstream description;
  description << "testing::PumaArcWorld(noise_px = 0, world_seed = " << world_seed << ", noise_seed = 1";
  if (!grid.empty()) {
    char x = 0, tail = 0;
    if (std::sscanf(grid.c_str(), "%d%c%d%c", &sim.sheet_grid.rows, &x, &sim.sheet_grid.cols, &tail) != 3 ||
        (x != 'x' && x != 'X')) {
      std::fprintf(stderr, "--flat-sheet-grid `%s`: ROWSxCOLS expected, e.g. 8x8\n", grid.c_str());
      return 2;
    }
    sim.flat_sheet = true;
    sim.sheet_grid.spacing_m = spacing_mm / 1000;
    // The origin dot (1.6 x 4 mm at 0.55 m, f_x 1000 px) is about 12 px in radius: its whole disc and
    // the detector's border check stay inside every image.
    sim.image_margin_px = 20;
    description << ", flat sheet grid " << grid << " of " << spacing_mm << " mm, margin " << sim.image_margin_px
                << " px";
  }
  description << ")";
  const selfcal::sim::SimResult world = selfcal::testing::PumaArcWorld(sim);
  if (!world.ok) {
    std::fprintf(stderr, "simulation failed: %s\n", world.message.c_str());
    return 3;
  }
  selfcal::sim::SequenceRenderOptions options;
  options.world_description = description.str();
  options.dot_radius_m = radius_mm / 1000;
  options.render.blur_sigma_px = blur_px;
  options.render.noise_std_grey = noise_grey;
  options.render.noise_seed = noise_seed;
  options.render.supersampling = supersampling;
  options.pose_indices = poses;
  const selfcal::Status status = detect_folder ? selfcal::simulation::WriteDetectFolder(world, options, folder)
                                               : selfcal::sim::RenderSequenceFolder(world, options, folder);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.ToString().c_str());
    return static_cast<int>(status.code());
  }
  std::printf("wrote %s\n", folder.c_str());
  return 0;
}
