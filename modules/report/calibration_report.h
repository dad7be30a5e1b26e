// Module report (ARCHITECTURE.md): every report as JSON, text and HTML, and nothing of files or exit codes
// (the app hands it the exit code and the input's provenance). This header (report.json, docs/report-format.md,
// schema docs/report.schema.json) and calibration_json_plots.h (the bundle's plot_data); study_report.h (the
// study tables and document, the bound sweep); html_report.h (report.html: one self-contained page of a
// report.json or study document, plotly.js handed in as text), html_writer.h (escaping, tables, the page),
// calibration_html_figures.h (the plotly figures); literature.h (the paper's Table 2 as data);
// terminal_progress.h (the progress line: bar, done/total, elapsed, time left; quiet off a terminal);
// plan_json.h (a plan's and its observability's figures for `plan --json`); image_residuals.h
// (image_residuals.csv, one row per image). Uses calibration, simulation, session, planning, kinematics,
// geometry, base.
//
// report.json of a calibration (schema: docs/report-format.md, "selfcal-calibration-report" version 3)
// and its on-screen summary. Every value in the JSON is SI with the unit in the key (_m, _rad, _px, _s);
// the text prints mm and degrees. The top level carries the chosen method's verdict and figures; the
// sections under "methods" have the same shape for every method that ran.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/calibrate.h"
#include "observations/observation_set.h"
#include "session/session_observations.h"

namespace selfcal::report {

inline constexpr const char* kCalibrationReportFormat = "selfcal-calibration-report";
inline constexpr int kCalibrationReportVersion = 3;

// What was read: the observations file, or a session directory (whose provenance is its manifest).
struct ReportInput {
  std::string kind;    // "observations" or "session"
  std::string path;
  std::string sha256;  // of the observations file, or of the session's session.json
  // A camera file that replaced the observations' camera (empty: none), its SHA-256 and the camera name
  // chosen in it (empty: the file's only camera).
  std::string camera_file{}, camera_file_sha256{}, camera_name{};
};

// What a session input adds to the report: the journal's counts and what a resume would repair.
struct SessionContext {
  session::JournalSummary summary;
  std::vector<std::string> findings;  // one line per torn tail or unrecorded image, left unchanged
};

// The application's side of the report: the process exit code it maps the verdict to, and (for a
// session) the session's counts and findings.
struct ReportContext {
  ReportInput input;
  int exit_code = 0;
  std::optional<SessionContext> session;  // empty when the input was not a session
};

nlohmann::json CalibrationReportJson(const ObservationSet& observations, const calibration::CalibrationReport& report,
                                     const ReportContext& context);

// The text summary: the configuration (eye-in-hand or eye-to-hand, of observations.robot.mount), the paper
// pipeline, then the bundle adjustment when it ran. Lines longer than kSummaryLineWidth characters are wrapped
// at spaces, the rest indented under the line's own indent.
void PrintCalibrationSummary(const ObservationSet& observations, const calibration::CalibrationReport& report,
                             std::ostream& out);
inline constexpr int kSummaryLineWidth = 120;

// The verdict and the held-out figure it rests on, for the last line of `selfcal calibrate`
// (docs/cli-output.md): "accepted: held-out 0.053 px (0.031 mm at the scene) on 10 verification poses".
// The figure is the verification poses' held-out RMS per coordinate, or without verification poses the
// cross-validation's pooled one; "no held-out figure" when there is neither.
std::string VerdictHeadline(const calibration::CalibrationReport& report);

// `text` with every line longer than `width` broken at spaces; the continuation lines take the line's
// own indent plus two spaces. A word longer than the width stays whole.
std::string WrapLines(const std::string& text, int width);

}  // namespace selfcal::report
