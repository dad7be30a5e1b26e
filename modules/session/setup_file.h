// setup.json, a session input (docs/session-format.md, "What selfcal run writes"): what a calibration
// needs beside the robot and the samples. Format `selfcal-session-setup` version 1: camera {width_px,
// height_px, fx_px (the nominal f_x), mu, cx_px, cy_px, k1}, pixel_noise_px, yardsticks and
// check_distances as [{dot_a, dot_b, length_m}].
#pragma once

#include <string>

#include "base/status.h"
#include "observations/observation_set.h"

namespace selfcal::session {

inline constexpr const char* kSetupFileName = "setup.json";
inline constexpr const char* kSetupFormatName = "selfcal-session-setup";
inline constexpr int kSetupFormatVersion = 1;

// The setup.json text (2-space indented JSON and a newline) of the camera, pixel noise, yardsticks and
// check distances of `setup`; its robot and poses are not part of it.
std::string SetupFileText(const ObservationSet& setup);

// Parses setup.json text into the camera, pixel_noise_px, yardsticks and check_distances of *set (its
// robot and poses are left alone). kInvalidInput naming `name` for another format or version, a missing or
// mistyped key, or a non-positive camera size, fx_px or pixel noise.
Status ParseSetupFile(const std::string& text, const std::string& name, ObservationSet* set);

}  // namespace selfcal::session
