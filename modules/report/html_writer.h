// The pieces of report.html shared by the calibration and the study pages: escaping, reading a JSON
// document that may lack keys, tables, and the page itself with plotly.js inlined.
//
// Self-contained: the page has no external source (no <script src>, <link href> or url()); plotly.js
// is inlined in one <script>, the figures' data in a <script type="application/json"> block, and a
// Content-Security-Policy (default-src 'none') keeps the browser from fetching anything, so the file
// opens offline and cannot leak a request.
//
// Escaping. Every text taken from a document goes through EscapeHtml before it reaches markup, through
// PlotText before it reaches a figure (plotly reads a few HTML tags and entities in its strings), and the
// figures' JSON through ScriptJson (no "<", ">" or "&" left, so "</script>" cannot end the block).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace selfcal::report::html {

// & < > " ' as entities; control characters other than tab and newline as U+FFFD.
std::string EscapeHtml(const std::string& text);

// A string for a figure's text, name or category: escaped as EscapeHtml, so plotly shows it verbatim.
std::string PlotText(const std::string& text);

// The JSON text of `value`, safe inside a <script> element: "<", ">", "&", U+2028 and U+2029 as \u escapes
// (valid JSON, the same value once parsed). Invalid UTF-8 is replaced by U+FFFD.
std::string ScriptJson(const nlohmann::json& value);

// The value at `path` (object keys), or null when a key is missing or a level is not an object.
const nlohmann::json& At(const nlohmann::json& j, std::initializer_list<const char*> path);

// A number, or NaN when the value is not one (null, absent, another type).
double Number(const nlohmann::json& v);

// A value as table text: numbers with `digits` significant digits (times `scale`), strings as they are,
// booleans yes/no, arrays of strings joined by ", ", null and absent as an em dash.
std::string Text(const nlohmann::json& v, int digits = 4, double scale = 1.0);
std::string Format(double v, int digits = 4);  // NaN and infinities as an em dash

// A table of escaped cells. A row may carry a CSS class (e.g. "fail").
class Table {
 public:
  explicit Table(std::vector<std::string> header) : header_(std::move(header)) {}
  void Row(std::vector<std::string> cells, const std::string& css_class = "");
  bool empty() const { return rows_.empty(); }
  std::string Html() const;

 private:
  std::vector<std::string> header_;
  std::vector<std::pair<std::string, std::vector<std::string>>> rows_;
};

// One page: headings, paragraphs and tables in order, figures where they are added.
class Page {
 public:
  explicit Page(std::string title) : title_(std::move(title)) {}
  void Heading(int level, const std::string& text, const std::string& anchor = "");
  void Paragraph(const std::string& text, const std::string& css_class = "");
  void Bullets(const std::vector<std::string>& items);
  void Add(const Table& table);
  // A plotly figure (data: array of traces, layout: object); `caption` under it. Its div id is the
  // page's own ("plot-N"), never taken from a document.
  void Figure(nlohmann::json data, nlohmann::json layout, const std::string& caption);
  // Markup built by this class's callers from escaped pieces only (e.g. the verdict box).
  void Markup(const std::string& html);
  int num_figures() const { return static_cast<int>(figures_.size()); }

  // The whole document, plotly_js (the library's source) inlined.
  std::string Render(const std::string& plotly_js) const;

 private:
  std::string title_;
  std::string body_;
  nlohmann::json figures_ = nlohmann::json::array();
};

// "plotly.js v2.6.3" from the library's banner comment, or "plotly.js" when it has none.
std::string PlotlyVersion(const std::string& plotly_js);

}  // namespace selfcal::report::html
