// report.html: the self-contained HTML page of a report.json document (format
// "selfcal-calibration-report", version 3: docs/report-format.md) or of a study's JSON document (format
// "selfcal-study", version 1), its plots drawn by plotly.js, which the caller reads and hands in as text
// (the report module touches no file). docs/report-format.md, section "report.html", says what the page
// shows.
//
// A calibration page: the verdict first (accepted or not, the message and any reasons), then the cameras
// and dots in 3-D, the reprojection residuals (histogram, per pose, over the image), the parameter
// corrections with +-1 sigma, the identifiability figures, the held-out results (reprojection and check
// distances), the paper pipeline's summary, the hand-eye and session blocks when present. A study page:
// its tables. Every text of the document is escaped (html_writer.h); a key the document lacks leaves its
// figure or row out, it never fails the page.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "base/status.h"

namespace selfcal::report {

inline constexpr const char* kStudyFormat = "selfcal-study";

// The page of `document`. kInvalidInput, naming the key and value, when the document is neither a
// calibration report of version 2 nor a study document of version 1.
Result<std::string> ReportHtml(const nlohmann::json& document, const std::string& plotly_js);

// The pages by kind (the document's format is not checked).
std::string CalibrationReportHtml(const nlohmann::json& report, const std::string& plotly_js);
std::string StudyReportHtml(const nlohmann::json& study, const std::string& plotly_js);

}  // namespace selfcal::report
