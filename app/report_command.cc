// selfcal report REPORT_JSON --out FILE.html: the HTML page of an existing report.json or study JSON.
// Read-only on its input.
#include "app/report_command.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "base/install_layout.h"
#include "io/atomic_file.h"
#include "io/report_json.h"
#include "report/html_report.h"

namespace selfcal::app {

namespace {

constexpr std::size_t kMaxPlotlyBytes = 64u << 20;  // plotly.js is 8.6 MB unminified, 3.8 MB minified

// Where plotly.js is looked for when neither --plotly-js nor SELFCAL_PLOTLY_JS names it, in order: the
// minified copy installed with selfcal (or made in its build tree), then Debian's python3-plotly.
std::vector<std::string> PlotlyCandidates() {
  std::vector<std::string> candidates;
  for (const SearchedPlace& place : ProgramLayout().data_dirs) candidates.push_back(place.directory + "/plotly.min.js");
  candidates.push_back("/usr/share/python3-plotly/plotly.js");
  candidates.push_back("/usr/lib/python3/dist-packages/plotly/package_data/plotly.min.js");
  return candidates;
}

Status PlotlyMissing(const std::string& what) {
  return Status::Error(ErrorCode::kInvalidInput,
                       "plotly.js " + what + ". report.html inlines it: install Debian's python3-plotly "
                       "(scripts/install-deps, or apt-get install python3-plotly), or name the file with "
                       "--plotly-js PATH or SELFCAL_PLOTLY_JS=PATH");
}

// plotly.js's text, from the first source that names a file (see report_command.h).
Result<std::string> ReadPlotlyJs(const std::string& option) {
  const char* env = std::getenv("SELFCAL_PLOTLY_JS");
  std::string path, source;
  if (!option.empty()) {
    path = option;
    source = "given by --plotly-js";
  } else if (env != nullptr && *env != '\0') {
    path = env;
    source = "named by the environment's SELFCAL_PLOTLY_JS";
  } else {
    std::string searched;
    std::error_code ec;
    for (const std::string& candidate : PlotlyCandidates()) {
      if (std::filesystem::exists(candidate, ec)) {
        path = candidate;
        break;
      }
      searched += (searched.empty() ? "" : ", ") + candidate;
    }
    if (path.empty()) return PlotlyMissing("not found (searched " + searched + ")");
    source = "the first of the places searched";
  }
  bool missing = false;
  Result<std::string> text = io::ReadFileCapped(path, kMaxPlotlyBytes, &missing);
  if (text.ok()) return text;
  return PlotlyMissing(std::string(missing ? "not found" : "not readable") + ": " + path + " (" + source + "; " +
                       text.status().message() + ")");
}

struct ReportArgs {
  std::string input;
  std::string out;
  std::string plotly_js;
};

}  // namespace

Status WriteHtmlReport(const nlohmann::json& document, const std::string& html_path, const std::string& plotly_js_path,
                       const std::string& document_name) {
  Result<std::string> plotly = ReadPlotlyJs(plotly_js_path);
  if (!plotly.ok()) return plotly.status();
  Result<std::string> page = report::ReportHtml(document, *plotly);
  if (!page.ok()) {
    return document_name.empty() ? page.status()
                                 : Status::Error(page.status().code(), document_name + ": " + page.status().message());
  }
  return io::WriteFileAtomically(html_path, *page);
}

void WriteHtmlBeside(const nlohmann::json& document, const std::string& html_path) {
  if (Status s = WriteHtmlReport(document, html_path); !s.ok()) {
    std::cerr << "selfcal: warning: " << html_path << " not written (report.json and the model are): " << s.message()
              << "\n";
    return;
  }
  std::cout << "HTML report: " << html_path << "\n";
}

Command AddReportCommand(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Write the self-contained HTML report (plots inlined, opens offline) of a report.json (calibrate) or a "
                "study's JSON output; reads its input only");
  cmd->add_option("input", args->input, "report.json of calibrate or simulate, or the JSON file of study --out")
      ->required();
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kFile, "HTML file to write (an existing one only with --force)")->required();
  cmd->add_option("--plotly-js", args->plotly_js,
                  "plotly.js to inline (default: $SELFCAL_PLOTLY_JS, else plotly.min.js installed with selfcal "
                  "(share/selfcal), else Debian's /usr/share/python3-plotly/plotly.js)");
  return [args]() {
    Result<nlohmann::json> document = io::ReadJsonFile(args->input);
    if (!document.ok()) return Fail(document.status());
    if (Status s = WriteHtmlReport(*document, args->out, args->plotly_js, args->input); !s.ok()) return Fail(s);
    std::cout << "HTML report: " << args->out << "\n";
    return 0;
  };
}

}  // namespace selfcal::app
