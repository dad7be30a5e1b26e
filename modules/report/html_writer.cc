#include "report/html_writer.h"

#include <algorithm>

#include <cctype>
#include <cmath>
#include <cstdio>

namespace selfcal::report::html {

namespace {

using nlohmann::json;

// The page's look: plain, readable, printable; no web font (nothing to fetch).
constexpr const char* kStyle = R"css(
body { font-family: "DejaVu Sans", Verdana, Arial, sans-serif; margin: 0 auto; max-width: 1200px; padding: 1em 2em;
       color: #222; background: #fff; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
h3 { font-size: 1.1em; margin-bottom: 0.3em; }
p.meta { color: #555; font-size: 0.9em; margin-top: 0; word-break: break-all; }
p.note, p.caption { color: #555; font-size: 0.9em; }
.verdict { border: 2px solid; border-radius: 6px; padding: 0.6em 1em; margin: 1em 0; }
.verdict.ok { border-color: #2e7d32; background: #e8f5e9; }
.verdict.refused { border-color: #c62828; background: #ffebee; }
.verdict.untested { border-color: #ef6c00; background: #fff3e0; }
.verdict .word { font-size: 1.4em; font-weight: bold; }
.verdict.ok .word { color: #2e7d32; }
.verdict.refused .word { color: #c62828; }
.verdict.untested .word { color: #ef6c00; }
table { border-collapse: collapse; margin: 0.5em 0 1em 0; font-size: 0.88em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
tr.fail td { background: #ffebee; }
tr.pass td { background: #f1f8e9; }
tr.fixed td { color: #777; }
.plot { width: 100%; min-height: 420px; }
footer { color: #777; font-size: 0.8em; margin-top: 3em; border-top: 1px solid #ccc; padding-top: 0.5em; }
)css";

// Runs plotly.js (inlined as text) once the page has been drawn, so that the verdict shows while its
// megabytes parse, then renders every figure and marks the body with the number rendered (the browser
// test waits for it). Any failure goes to the console, where the test looks for errors.
constexpr const char* kInitScript = R"js(
(function () {
  function plots() {
    (0, eval)(document.getElementById('selfcal-plotly').textContent);
    var figures = JSON.parse(document.getElementById('selfcal-figures').textContent);
    var config = {displaylogo: false, responsive: true};
    Promise.all(figures.map(function (f) { return Plotly.newPlot(f.div, f.data, f.layout, config); }))
      .then(function () { document.body.setAttribute('data-plots-rendered', String(figures.length)); },
            function (e) { console.error('selfcal report: a figure failed: ' + e); });
  }
  requestAnimationFrame(function () { setTimeout(plots, 0); });
})();
)js";

// Nothing but the inline script and style may run or load: no request leaves the page.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'unsafe-inline' 'unsafe-eval'; style-src 'unsafe-inline'; "
    "img-src data: blob:; font-src data:";

// Length of the UTF-8 sequence starting at s[i] (1..4), or 0 when it is not valid UTF-8.
int Utf8Length(const std::string& s, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  int n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (int k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  }
  return n;
}

// `text` with `from` replaced by `to` wherever it occurs, ignoring ASCII case.
std::string ReplaceIgnoringCase(const std::string& text, const std::string& from, const std::string& to) {
  std::string out;
  out.reserve(text.size());
  // A pattern that starts with a character without case (here '<') jumps to its next occurrence: the
  // 3.5 MB of plotly.js are copied in blocks, not compared character by character.
  const bool jump = !from.empty() && !std::isalpha(static_cast<unsigned char>(from[0]));
  for (size_t i = 0; i < text.size();) {
    if (jump) {
      const size_t next = std::min(text.find(from[0], i), text.size());
      out.append(text, i, next - i);
      i = next;
      if (i == text.size()) break;
    }
    bool match = i + from.size() <= text.size();
    for (size_t k = 0; match && k < from.size(); ++k) match = std::tolower(text[i + k]) == std::tolower(from[k]);
    if (match) {
      out += to;
      i += from.size();
    } else {
      out += text[i++];
    }
  }
  return out;
}

}  // namespace

std::string EscapeHtml(const std::string& text) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const int n = Utf8Length(text, i);
    if (n == 0) {
      out += "&#xFFFD;";
      ++i;
      continue;
    }
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default:
        if ((c < 0x20 && c != '\t' && c != '\n') || c == 0x7F) {
          out += "&#xFFFD;";
        } else {
          out.append(text, i, n);
        }
    }
    i += n;
  }
  return out;
}

std::string PlotText(const std::string& text) { return EscapeHtml(text); }

std::string ScriptJson(const json& value) {
  const std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '<') {
      out += "\\u003c";
    } else if (c == '>') {
      out += "\\u003e";
    } else if (c == '&') {
      out += "\\u0026";
    } else if (c == '\xE2' && i + 2 < text.size() && text[i + 1] == '\x80' && (text[i + 2] == '\xA8' || text[i + 2] == '\xA9')) {
      out += text[i + 2] == '\xA8' ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      out += c;
    }
  }
  return out;
}

const json& At(const json& j, std::initializer_list<const char*> path) {
  static const json kNull;
  const json* node = &j;
  for (const char* key : path) {
    if (!node->is_object()) return kNull;
    const auto it = node->find(key);
    if (it == node->end()) return kNull;
    node = &*it;
  }
  return *node;
}

double Number(const json& v) { return v.is_number() ? v.get<double>() : NAN; }

std::string Format(double v, int digits) {
  if (!std::isfinite(v)) return "\u2014";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", digits, v);
  return buffer;
}

std::string Text(const json& v, int digits, double scale) {
  if (v.is_number_integer() && scale == 1.0) return std::to_string(v.get<long long>());
  if (v.is_number()) return Format(v.get<double>() * scale, digits);
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_array()) {
    std::string out;
    for (const json& item : v) out += (out.empty() ? "" : ", ") + Text(item, digits, scale);
    return out.empty() ? "(none)" : out;
  }
  if (v.is_object()) return v.dump(-1, ' ', false, json::error_handler_t::replace);
  return "\u2014";
}

void Table::Row(std::vector<std::string> cells, const std::string& css_class) {
  rows_.emplace_back(css_class, std::move(cells));
}

std::string Table::Html() const {
  std::string out = "<table>\n<tr>";
  for (const std::string& h : header_) out += "<th>" + EscapeHtml(h) + "</th>";
  out += "</tr>\n";
  for (const auto& [css_class, cells] : rows_) {
    out += css_class.empty() ? "<tr>" : "<tr class=\"" + EscapeHtml(css_class) + "\">";
    for (const std::string& c : cells) out += "<td>" + EscapeHtml(c) + "</td>";
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

void Page::Heading(int level, const std::string& text, const std::string& anchor) {
  const std::string tag = "h" + std::to_string(level);
  body_ += "<" + tag + (anchor.empty() ? "" : " id=\"" + EscapeHtml(anchor) + "\"") + ">" + EscapeHtml(text) + "</" +
           tag + ">\n";
}

void Page::Paragraph(const std::string& text, const std::string& css_class) {
  body_ += (css_class.empty() ? "<p>" : "<p class=\"" + EscapeHtml(css_class) + "\">") + EscapeHtml(text) + "</p>\n";
}

void Page::Bullets(const std::vector<std::string>& items) {
  if (items.empty()) return;
  body_ += "<ul>\n";
  for (const std::string& item : items) body_ += "<li>" + EscapeHtml(item) + "</li>\n";
  body_ += "</ul>\n";
}

void Page::Add(const Table& table) { body_ += table.Html(); }

void Page::Markup(const std::string& html) { body_ += html; }

void Page::Figure(json data, json layout, const std::string& caption) {
  const std::string id = "plot-" + std::to_string(figures_.size() + 1);
  body_ += "<div class=\"plot\" id=\"" + id + "\"></div>\n";
  if (!caption.empty()) Paragraph(caption, "caption");
  layout["autosize"] = true;
  if (!layout.contains("margin")) layout["margin"] = {{"t", 50}, {"l", 70}, {"r", 30}, {"b", 60}};
  figures_.push_back({{"div", id}, {"data", std::move(data)}, {"layout", std::move(layout)}});
}

std::string Page::Render(const std::string& plotly_js) const {
  // The library's text may not end the script element early.
  const std::string library = ReplaceIgnoringCase(ReplaceIgnoringCase(plotly_js, "</script", "<\\/script"), "<!--", "<\\!--");
  std::string out;
  out.reserve(library.size() + body_.size() + 4096);
  out += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  out += "<meta http-equiv=\"Content-Security-Policy\" content=\"" + std::string(kContentSecurityPolicy) + "\">\n";
  out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  out += "<title>" + EscapeHtml(title_) + "</title>\n<style>" + kStyle + "</style>\n";
  out += "</head>\n<body>\n";
  out += body_;
  out += "<footer>Plots: " + EscapeHtml(PlotlyVersion(plotly_js)) +
         ", inlined: this file opens offline and loads nothing.</footer>\n";
  // The library as text, run by the init script after the first paint: the verdict shows first.
  out += "<script type=\"text/plain\" id=\"selfcal-plotly\">\n" + library + "\n</script>\n";
  out += "<script type=\"application/json\" id=\"selfcal-figures\">" + ScriptJson(figures_) + "</script>\n";
  out += "<script>" + std::string(kInitScript) + "</script>\n</body>\n</html>\n";
  return out;
}

std::string PlotlyVersion(const std::string& plotly_js) {
  const size_t at = plotly_js.substr(0, 400).find("plotly.js v");
  if (at == std::string::npos) return "plotly.js";
  size_t end = at + 11;
  while (end < plotly_js.size() && (std::isdigit(static_cast<unsigned char>(plotly_js[end])) || plotly_js[end] == '.')) ++end;
  return plotly_js.substr(at, end - at);
}

}  // namespace selfcal::report::html
