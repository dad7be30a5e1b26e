// The dot identifier options shared by `selfcal run` and `selfcal name-dots` (acquisition/identifiers.h),
// so that the ids the operator saw named are the ids the run records.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "acquisition/identifiers.h"

namespace selfcal::app {

struct IdentifySettings {
  std::string method;  // order | grid | apriltag | reference; empty: the backend's default
  int grid_rows = 10;
  int grid_cols = 10;
  std::string grid_origin = "larger-dot";  // larger-dot | none
  double tag_side_mm = 0;
  std::vector<double> tag_dots_mm;  // x1,y1,x2,y2,... in the tag's frame
  double tag_tolerance_px = 3.0;
  double reference_gate_px = 4.0;
};

// Registers --identify and its options on `cmd`; `default_help` says what an empty --identify means.
void AddIdentifyOptions(CLI::App* cmd, IdentifySettings* settings, const std::string& default_help);

// The identifier options of `settings` with `fallback` as the method when none was given (SI: mm to m).
Result<acquisition::IdentifierOptions> ToIdentifierOptions(const IdentifySettings& settings,
                                                           const std::string& fallback);

// The identifier of `settings` (method `fallback` when none was given), with the reference dots of the
// setup text `setup_text` (named `setup_name` in messages) when the method is reference.
Result<std::unique_ptr<acquisition::DotIdentifier>> MakeIdentifier(const IdentifySettings& settings,
                                                                   const std::string& fallback,
                                                                   const std::string& setup_text,
                                                                   const std::string& setup_name);

}  // namespace selfcal::app
