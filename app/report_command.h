// report.html: `selfcal report REPORT_JSON --out FILE.html` (a report.json or a study's JSON output), and
// the same page beside report.json for `calibrate` (report/html_report.h draws it).
//
// plotly.js is inlined into the page; this side finds and reads it: --plotly-js PATH when given, else
// the environment's SELFCAL_PLOTLY_JS, else the first that exists of plotly.min.js in the data directories
// of base/install_layout.h (share/selfcal installed with the program; for a program run from its build
// tree also the build directory, where CMake minifies it), Debian 12's python3-plotly
// (/usr/share/python3-plotly/plotly.js) and pip's package_data copy. A missing file is a kInvalidInput
// naming every place searched and how to install it.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "base/status.h"

namespace selfcal::app {

// The page of `document` written atomically to `html_path`; nothing written on failure. `plotly_js_path`:
// the --plotly-js option ("" when not given); `document_name` (e.g. its path) prefixes the document's
// own errors.
Status WriteHtmlReport(const nlohmann::json& document, const std::string& html_path,
                       const std::string& plotly_js_path = "", const std::string& document_name = "");

// calibrate's report.html beside its report.json: prints where it is, or a warning saying why it was not
// written (not a failure: report.json and the model are written whatever happens here).
void WriteHtmlBeside(const nlohmann::json& document, const std::string& html_path);

}  // namespace selfcal::app
