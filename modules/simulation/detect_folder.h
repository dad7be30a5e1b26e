// A simulated cell's recording as a folder of images and robot poses, the input of `selfcal detect`
// (docs/detect.md): the path a user's own data set takes (detect, then calibrate), on a world whose
// truth is known. The folder holds
//   frame_NNNNNN.png, index.yaml, truth.yaml  the rendered sequence (sim/render_sequence.h: the images as
//                                             the simulated camera grabs them, and every dot's true
//                                             projected centre per frame)
//   poses.yaml                                a selfcal-poses list: each image's joint angles (the world's
//                                             joints, exact), its verification poses `role: verification`
//   hidden_truth.json                         the hidden model (selfcal-sim-truth): every kinematic
//                                             parameter's true value by name (SI, unit in the key),
//                                             whether it was perturbed, the true f_x and flange_from_cam
// No selfcal command reads hidden_truth.json or truth.yaml: they are for scoring.
#pragma once

#include <string>

#include "base/status.h"
#include "sim/render_sequence.h"
#include "sim/sim_world.h"

namespace selfcal::simulation {

inline constexpr const char* kDetectPosesName = "poses.yaml";
inline constexpr const char* kHiddenTruthName = "hidden_truth.json";

// Renders every pose of `world` (options.pose_indices is ignored: a data set has all of them) into the
// new folder `folder` and writes the poses list and the hidden truth beside the images. Errors as
// sim::RenderSequenceFolder and io's writers (kInvalidInput for bad options or an existing folder).
Status WriteDetectFolder(const sim::SimResult& world, const sim::SequenceRenderOptions& options,
                         const std::string& folder);

}  // namespace selfcal::simulation
