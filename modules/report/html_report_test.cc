#include "report/html_report.h"

#include <iomanip>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "report/calibration_report.h"
#include "report/html_writer.h"
#include "support/sim_worlds.h"

namespace selfcal::report {
namespace {

using html::At;
using nlohmann::json;

// A stand-in for plotly.js: the page only inlines it.
constexpr const char* kFakePlotly = "/**\n* plotly.js v9.8.7\n*/\nwindow.Plotly = {};\n";
constexpr const char* kHostile = "<script>alert(1)</script><img src=x onerror=alert(2)>&amp;\"'";

// The figures' JSON block of a page, parsed.
json Figures(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"selfcal-figures\">";
  const size_t begin = page.find(open);
  if (begin == std::string::npos) return nullptr;
  const size_t end = page.find("</script>", begin);
  return json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(HtmlWriter, EscapesMarkupControlsAndBadUtf8) {
  EXPECT_EQ(html::EscapeHtml("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
  EXPECT_EQ(html::EscapeHtml("tab\tnew\nbell\x07"), "tab\tnew\nbell&#xFFFD;");
  EXPECT_EQ(html::EscapeHtml("\xC3\xA9t\xC3\xA9"), "\xC3\xA9t\xC3\xA9");  // UTF-8 kept
  EXPECT_EQ(html::EscapeHtml("bad \xC3( end \xFF"), "bad &#xFFFD;( end &#xFFFD;");
}

TEST(HtmlWriter, ScriptJsonCannotCloseItsElementAndParsesBack) {
  const json value = {{"text", "</script><!-- & \xE2\x80\xA8 >"}, {"n", 1.5}};
  const std::string text = html::ScriptJson(value);
  EXPECT_EQ(text.find('<'), std::string::npos) << text;
  EXPECT_EQ(text.find('>'), std::string::npos) << text;
  EXPECT_EQ(text.find('&'), std::string::npos) << text;
  EXPECT_EQ(text.find("\xE2\x80\xA8"), std::string::npos) << text;
  EXPECT_EQ(json::parse(text), value);
}

TEST(HtmlWriter, InlinedLibraryCannotCloseItsScript) {
  html::Page page("t");
  const std::string out = page.Render("var s = '</SCRIPT><script src=\"https://example.invalid/x.js\">';");
  EXPECT_EQ(Count(out, "</script>") + Count(out, "</SCRIPT>"), 3);  // the library's, the figures', the init's
  EXPECT_NE(out.find("<\\/script"), std::string::npos);
}

class HtmlReportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim::SimResult world = testing::PumaArcWorld(0.3, 2, 2);
    // Pose ids with markup in them: they reach tables, hover texts and category axes.
    for (PoseObservation& pose : world.observations.poses) pose.id = "<b>" + pose.id + "&'\"";
    const calibration::CalibrationReport report = calibration::Calibrate(world.observations, {});
    document_ = new json(CalibrationReportJson(world.observations, report, {{"observations", kHostile, "ab"}, 0, {}}));
    (*document_)["message"] = kHostile;
  }
  static void TearDownTestSuite() { delete document_; }
  static json* document_;
};
json* HtmlReportTest::document_ = nullptr;

TEST_F(HtmlReportTest, EveryDocumentTextIsEscapedAndNothingIsFetched) {
  ASSERT_EQ(At(*document_, {"accepted"}), true) << (*document_)["methods"]["bundle"]["message"];
  const Result<std::string> page = ReportHtml(*document_, kFakePlotly);
  ASSERT_TRUE(page.ok()) << page.status().message();
  const std::string& html = *page;
  EXPECT_EQ(html.find("alert(1)</script>"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_EQ(html.find("<b>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;&lt;img src=x onerror=alert(2)&gt;&amp;amp;"),
            std::string::npos);
  // Self-contained: three inline scripts, no source or link anywhere, no URL at all.
  EXPECT_EQ(Count(html, "<script"), 3);
  EXPECT_FALSE(std::regex_search(html, std::regex("<(script|link|img|iframe|embed|object)[^>]*(src|href)\\s*=",
                                                  std::regex::icase)));
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_NE(html.find("default-src 'none'"), std::string::npos);
  EXPECT_NE(html.find(kFakePlotly), std::string::npos);
  EXPECT_NE(html.find("plotly.js v9.8.7"), std::string::npos);
  // Pose ids reach the figures escaped, as plotly shows them verbatim.
  const json figures = Figures(html);
  ASSERT_TRUE(figures.is_array());
  EXPECT_NE(figures.dump().find("&lt;b&gt;"), std::string::npos);
  EXPECT_EQ(figures.dump().find("<b>"), std::string::npos);
}

// The verdict comes before every figure; every figure has its div; the figures hold the report's data.
TEST_F(HtmlReportTest, VerdictFirstAndFiguresCarryTheReportsData) {
  const std::string html = *ReportHtml(*document_, kFakePlotly);
  const json figures = Figures(html);
  ASSERT_TRUE(figures.is_array());
  // Scene, histogram, per pose, over the image, corrections, correlations, held-out RMS and test, checks.
  ASSERT_EQ(figures.size(), 9u);
  for (const json& f : figures) {
    EXPECT_NE(html.find("<div class=\"plot\" id=\"" + f["div"].get<std::string>() + "\">"), std::string::npos);
    EXPECT_FALSE(f["data"].empty()) << f["layout"]["title"];
  }
  const size_t verdict = html.find("id=\"verdict\"");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_LT(verdict, html.find("<div class=\"plot\""));
  EXPECT_NE(html.find(">Accepted<"), std::string::npos);
  const json& bundle = (*document_)["methods"]["bundle"];
  const json& dots = figures[0]["data"][0];
  EXPECT_EQ(dots["x"].size(), bundle["plot_data"]["dots_in_base"].size());
  EXPECT_EQ(dots["x"][0].get<double>(), bundle["plot_data"]["dots_in_base"][0]["xyz_m"][0].get<double>() * 1e3);
  const json& histogram = figures[1]["data"][0];
  EXPECT_EQ(histogram["x"].size(), bundle["num_observations"].get<size_t>());
  EXPECT_EQ(figures[1]["data"][1]["x"].size(),
            (*document_)["heldout_reprojection"]["calibrated_model"]["overall"]["num_residuals"].get<size_t>());
  // Corrections: one point per free parameter, lengths and angles apart.
  EXPECT_EQ(figures[4]["data"][0]["x"].size() + figures[4]["data"][1]["x"].size(), bundle["free"].size());
}

// The verdict is drawn before plotly.js parses (the library after the body's text), and the page holds one
// held-out chi-square test: the verdict's, at the stated noise; the estimated-noise one is not in the table.
TEST_F(HtmlReportTest, VerdictBeforeTheLibraryAndOneHeldOutTest) {
  const std::string html = *ReportHtml(*document_, kFakePlotly);
  const size_t verdict = html.find("id=\"verdict\"");
  const size_t library = html.find("window.Plotly = {}");
  ASSERT_NE(verdict, std::string::npos);
  ASSERT_NE(library, std::string::npos);
  EXPECT_LT(verdict, library);
  EXPECT_GT(library, html.find("<body>"));
  const json& calibrated = (*document_)["heldout_reprojection"]["calibrated_model"];
  const json& stated = calibrated["overall_at_stated_noise"];
  const json& estimated = calibrated["overall"];
  ASSERT_TRUE(stated.is_object());
  ASSERT_NE(stated["chi_square"].get<double>(), estimated["chi_square"].get<double>());
  // Table cells print 5 significant digits.
  std::ostringstream stated_text, estimated_text;
  stated_text << "<td>" << std::setprecision(5) << stated["chi_square_limit"].get<double>() << "</td>";
  estimated_text << "<td>" << std::setprecision(5) << estimated["chi_square_limit"].get<double>() << "</td>";
  EXPECT_NE(html.find(stated_text.str()), std::string::npos) << stated_text.str();
  EXPECT_EQ(html.find(estimated_text.str()), std::string::npos) << estimated_text.str();
  EXPECT_NE(html.find("calibrated (the verdict&#39;s test)"), std::string::npos);
}

TEST_F(HtmlReportTest, RefusesOtherDocumentsNamingTheKey) {
  json other = {{"format", "something-else"}, {"version", 2}};
  Result<std::string> page = ReportHtml(other, kFakePlotly);
  ASSERT_FALSE(page.ok());
  EXPECT_EQ(page.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(page.status().message().find("key `format`: \"something-else\""), std::string::npos) << page.status().message();
  json old = *document_;
  old["version"] = 2;  // the version before the camera poses were named for what they are
  page = ReportHtml(old, kFakePlotly);
  ASSERT_FALSE(page.ok());
  EXPECT_NE(page.status().message().find("key `version`: 2"), std::string::npos) << page.status().message();
  EXPECT_FALSE(ReportHtml(json::array(), kFakePlotly).ok());
}

// A report with almost nothing in it (e.g. a refusal before any method ran) still renders, with notes.
TEST(HtmlReport, SparseReportRendersWithNotes) {
  const json sparse = {{"format", kCalibrationReportFormat}, {"version", kCalibrationReportVersion},
                       {"accepted", false}, {"verdict", "invalid_input"}, {"message", "bad options"},
                       {"reasons", {"the first reason", {{"code", "held_out"}, {"message", "the second <reason>"}}}}};
  const Result<std::string> page = ReportHtml(sparse, kFakePlotly);
  ASSERT_TRUE(page.ok()) << page.status().message();
  EXPECT_NE(page->find("Not accepted (invalid_input)"), std::string::npos);
  EXPECT_NE(page->find("<li>the first reason</li>"), std::string::npos);
  EXPECT_NE(page->find("<li>held_out: the second &lt;reason&gt;</li>"), std::string::npos);
  EXPECT_NE(page->find("no camera poses or dots to show"), std::string::npos);
  EXPECT_EQ(Figures(*page).size(), 0u);
}

TEST(HtmlReport, StudyTablesAreRenderedAndEscaped) {
  json cell = {{"trajectory", "<i>initial</i>"}, {"noise_px", 0.2}, {"runs", 3}, {"runs_failed", 0},
               {"paper_pipeline", {{"position_mm", {{"n", 30}, {"mean", 0.123}, {"sd", 0.045}}}}},
               {"fig6_3d_error_mm", {{"nominal_model", {{"n", 3}, {"mean", 2.5}, {"sd", 0.5}}},
                                     {"calibrated", {{"n", 3}, {"mean", 0.25}, {"sd", 0.05}}}}}};
  const json study = {{"format", kStudyFormat}, {"version", 1}, {"runs_per_cell", 3}, {"cells", {cell}}};
  const Result<std::string> page = ReportHtml(study, kFakePlotly);
  ASSERT_TRUE(page.ok()) << page.status().message();
  EXPECT_NE(page->find("<td>&lt;i&gt;initial&lt;/i&gt; @ 0.2 px</td><td>paper pipeline</td><td>0.123 \u00b1 0.045</td>"),
            std::string::npos);
  EXPECT_EQ(page->find("<i>"), std::string::npos);
  const json figures = Figures(*page);
  ASSERT_EQ(figures.size(), 1u);
  EXPECT_EQ(figures[0]["data"][0]["y"][0], 2.5);
}

}  // namespace
}  // namespace selfcal::report
