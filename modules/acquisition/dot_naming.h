// Naming the dots of one frame for the operator (`selfcal name-dots`, docs/real-hardware-quickstart.md):
// detect with the session's detector options, name with a DotIdentifier (identifiers.h), draw every dot
// with its id, and put the ids the operator chose into the setup (the yardstick's ends) together with the
// named dots themselves (setup.json's reference_dots: what `run --identify reference` names the first
// frame by). Nothing here touches a file or a device.
#pragma once

#include <string>
#include <vector>

#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>

#include "acquisition/session_runner.h"
#include "observations/observation_set.h"
#include "session/setup_file.h"

namespace selfcal::acquisition {

struct NamingResult {
  tracking::DetectionReport detections;
  std::vector<tracking::PreviousDot> named;  // sorted by id; empty when the identifier failed
  std::string identifier_message;            // why the identifier named nothing (empty on success)
  // For each detection, its id (-1: left unnamed). Same order as detections.dots.
  std::vector<int> id_of_detection;
};

// Detects the dots of `frame` with `detector` and names them with `identifier`. A failing identifier is not
// an error here: the result says why, and every detection is still drawn (unnamed).
NamingResult NameDots(const capture::Frame& frame, DotIdentifier* identifier,
                      const tracking::DotDetectorOptions& detector);

// `image` in colour with every detection circled and its id written beside it (named: green, unnamed: red
// and "?").
vpImage<vpRGBa> AnnotateDots(const vpImage<unsigned char>& image, const NamingResult& naming);

// The PNG bytes of a colour image. kInvalidInput on an empty image or an encoder failure.
Result<std::string> EncodeColourPng(const vpImage<vpRGBa>& image);

struct YardstickChoice {
  int dot_a = -1;
  int dot_b = -1;
  double length_m = 0;
};

// Puts the naming into the setup: the named dots become naming->reference_dots (with `source` as the
// reference image) and, when `yardstick` is given, it replaces setup->yardsticks. kInvalidInput when a
// yardstick id is not a dot of this frame, the two are the same, or the length is not positive; nothing is
// changed then. Returns, in *warnings, each id of the setup's yardsticks and check distances that this
// frame did not name.
Status ApplyNaming(const NamingResult& naming, const YardstickChoice* yardstick, const std::string& source,
                   ObservationSet* setup, session::SetupNaming* setup_naming, std::vector<std::string>* warnings);

}  // namespace selfcal::acquisition
