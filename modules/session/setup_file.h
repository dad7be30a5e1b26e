// setup.json, a session input (docs/session-format.md, "What selfcal run writes"): what a calibration
// needs beside the robot and the samples. Format `selfcal-session-setup` version 1: camera {width_px,
// height_px, fx_px (the nominal f_x), mu, cx_px, cy_px, k1}, pixel_noise_px, yardsticks and
// check_distances as [{dot_a, dot_b, length_m}]; optional (written by `selfcal name-dots`, ignored by
// readers that do not need them): reference_dots [{id, u_px, v_px, area_px2}] (the named dots of the frame
// the operator saw) and reference_image (where that frame came from). Optional "configuration" (eye_in_hand,
// the default, or eye_to_hand) and, for eye_to_hand only and then required, "base_from_cam" {translation_m:
// [x, y, z], rotation: [[r00, r01, r02], [r10, ...], [r20, ...]]}: the nominal fixed camera in the base frame.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "observations/observation_set.h"

namespace selfcal::session {

inline constexpr const char* kSetupFileName = "setup.json";
inline constexpr const char* kSetupFormatName = "selfcal-session-setup";
inline constexpr int kSetupFormatVersion = 1;

// A dot as the operator saw it named in one frame (pixels as tracking/dot_detector.h).
struct ReferenceDot {
  int id = -1;
  double u_px = 0;
  double v_px = 0;
  double area_px2 = 0;
};

// The optional naming keys of setup.json. Empty: the keys are not written.
struct SetupNaming {
  std::vector<ReferenceDot> reference_dots;
  std::string reference_image;
};

// The setup.json text (2-space indented JSON and a newline) of the camera, pixel noise, yardsticks and
// check distances of `setup`, and the naming keys of `naming` when it has any; of the robot only its mount
// and, in eye-to-hand, its base_from_cam (an eye-in-hand setup is written as before the keys existed).
std::string SetupFileText(const ObservationSet& setup, const SetupNaming& naming = {});

// Parses setup.json text into the camera, pixel_noise_px, yardsticks and check_distances of *set, the
// configuration into set->robot.mount and set->robot.base_from_cam (the rest of the robot and the poses are
// left alone) and, when `naming` is given, the optional naming keys. kInvalidInput
// when it is not JSON, another format or version, a key is missing or mistyped (integers must be
// integers), a camera size, fx_px or the pixel noise is not positive, or reference dots repeat an id or
// have a negative area: every problem as "<name>:<line>: ..." (session/json_fields.h), joined by "; ".
Status ParseSetupFile(const std::string& text, const std::string& name, ObservationSet* set,
                      SetupNaming* naming = nullptr);

}  // namespace selfcal::session
