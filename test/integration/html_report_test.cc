// selfcal report and calibrate's report.html: files in, files out, exit codes (the page's content is
// tested in modules/report, its rendering in html_report_browser_test.py).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::RunBinary;
using testing::RunSelfcal;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The binary with plotly.js named by the environment.
int RunWithPlotly(const std::string& plotly, const std::string& arguments, std::string* output) {
  return RunBinary("SELFCAL_PLOTLY_JS=" + plotly + " " + SELFCAL_BINARY, arguments, output);
}

class ReportCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::FreshDir("html_report", "sim"));
    std::string output;
    simulated_ = RunSelfcal("simulate --points --seed 4 --out " + dir_->string(), &output) == 0;
    if (!simulated_) std::cerr << output;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  void SetUp() override { ASSERT_TRUE(simulated_) << "simulate --points failed"; }
  static fs::path* dir_;
  static bool simulated_;
};
fs::path* ReportCommand::dir_ = nullptr;
bool ReportCommand::simulated_ = false;

// calibrate (through simulate) wrote report.html; `report` of its report.json writes the same bytes and
// leaves report.json as it was.
TEST_F(ReportCommand, ReportOfReportJsonIsCalibratesPageAndLeavesTheInputAlone) {
  const fs::path html = *dir_ / "report.html";
  ASSERT_TRUE(fs::exists(html));
  const std::string page = ReadFile(html);
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(page.find("id=\"verdict\""), std::string::npos);
  EXPECT_NE(page.find("Plots: plotly.js v"), std::string::npos);  // inlined: its banner named in the footer
  const fs::path input = *dir_ / "report.json";
  const std::string before = ReadFile(input);
  const fs::file_time_type modified = fs::last_write_time(input);
  const fs::path again = *dir_ / "again.html";
  std::string output;
  ASSERT_EQ(RunSelfcal("report " + input.string() + " --out " + again.string(), &output), 0) << output;
  EXPECT_NE(output.find("HTML report: " + again.string()), std::string::npos) << output;
  EXPECT_EQ(ReadFile(again), page);
  EXPECT_EQ(ReadFile(input), before);
  EXPECT_EQ(fs::last_write_time(input), modified);
}

// Without plotly.js: `report` fails naming the file and the package, and writes nothing.
TEST_F(ReportCommand, MissingPlotlyFailsNamingTheFileAndWritesNothing) {
  const fs::path out = *dir_ / "none.html";
  std::string output;
  EXPECT_EQ(RunWithPlotly("/nonexistent/plotly.js", "report " + (*dir_ / "report.json").string() + " --out " +
                                                        out.string(), &output), 2);
  EXPECT_NE(output.find("plotly.js not found: /nonexistent/plotly.js"), std::string::npos) << output;
  EXPECT_NE(output.find("SELFCAL_PLOTLY_JS"), std::string::npos) << output;
  EXPECT_NE(output.find("apt-get install python3-plotly"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
  // The option wins over the environment.
  EXPECT_EQ(RunSelfcal("report " + (*dir_ / "report.json").string() + " --out " + out.string() +
                           " --plotly-js /nonexistent/other.js", &output), 2);
  EXPECT_NE(output.find("/nonexistent/other.js (given by --plotly-js"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
}

// Without plotly.js calibrate still writes report.json and the model, and says the page was not written.
TEST_F(ReportCommand, CalibrateWithoutPlotlyWritesEverythingButThePage) {
  const fs::path out = *dir_ / "no_plotly";
  std::string output;
  ASSERT_EQ(RunWithPlotly("/nonexistent/plotly.js", "calibrate " + (*dir_ / "observations.yaml").string() +
                                                        " --seed 4 --out " + out.string(), &output), 0) << output;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  EXPECT_TRUE(fs::exists(out / "calibrated_model.yaml"));
  EXPECT_FALSE(fs::exists(out / "report.html"));
  EXPECT_NE(output.find("warning: " + (out / "report.html").string() + " not written"), std::string::npos) << output;
  EXPECT_NE(output.find("python3-plotly"), std::string::npos) << output;
}

// --no-html: everything but the page, and no warning about it; the page written by default inlines a
// minified plotly.js when the build made one (its licence banner kept on top).
TEST_F(ReportCommand, NoHtmlWritesEverythingButThePageAndTheDefaultPageKeepsPlotlysLicence) {
  const fs::path out = *dir_ / "no_html";
  std::string output;
  ASSERT_EQ(RunSelfcal("calibrate " + (*dir_ / "observations.yaml").string() + " --seed 4 --no-html --out " +
                           out.string(), &output), 0) << output;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  EXPECT_TRUE(fs::exists(out / "calibrated_model.yaml"));
  EXPECT_FALSE(fs::exists(out / "report.html"));
  EXPECT_EQ(output.find("report.html"), std::string::npos) << output;
  const std::string page = ReadFile(*dir_ / "report.html");
  EXPECT_NE(page.find("Licensed under the MIT license"), std::string::npos);
}

// Other JSON, a missing input and an output over the input: refused (exit 2), nothing written.
TEST_F(ReportCommand, RefusesOtherDocumentsAndWritingOverItsInput) {
  const fs::path out = *dir_ / "refused.html";
  std::string output;
  EXPECT_EQ(RunSelfcal("report " + (*dir_ / "truth.json").string() + " --out " + out.string(), &output), 2);
  EXPECT_NE(output.find((*dir_ / "truth.json").string() + ": key `format`"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("report " + (*dir_ / "missing.json").string() + " --out " + out.string(), &output), 2);
  EXPECT_NE(output.find("missing.json"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
  const fs::path input = *dir_ / "report.json";
  const std::string before = ReadFile(input);
  EXPECT_EQ(RunSelfcal("report " + input.string() + " --out " + input.string(), &output), 2);
  EXPECT_NE(output.find("an input of this command"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("report " + input.string() + " --out " + input.string() + " --force", &output), 2);
  EXPECT_EQ(ReadFile(input), before);
}

}  // namespace
}  // namespace selfcal
