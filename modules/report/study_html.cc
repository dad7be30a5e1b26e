// The study page of report.html (html_report.h): the study's tables from its JSON document (study_json.cc),
// and its Fig. 6 as a plot.
#include <string>
#include <vector>

#include "report/html_report.h"
#include "report/html_writer.h"

namespace selfcal::report {

namespace {

using html::At;
using html::Page;
using html::Table;
using html::Text;
using nlohmann::json;

// "mean +- sd" of a Stat ({n, mean, sd, rms, p90, max}).
std::string MeanSd(const json& stat) {
  if (At(stat, {"n"}) == 0) return "\u2014";
  return Text(At(stat, {"mean"})) + " \u00b1 " + Text(At(stat, {"sd"}));
}
std::string Rms(const json& stat) { return At(stat, {"n"}) == 0 ? "\u2014" : Text(At(stat, {"rms"})); }

std::string Cell(const json& c) { return Text(At(c, {"trajectory"})) + " @ " + Text(At(c, {"noise_px"})) + " px"; }

void SettingsTable(const json& s, Page* page) {
  Table t({"setting", "value"});
  t.Row({"runs per cell", Text(At(s, {"runs_per_cell"}))});
  t.Row({"seed", Text(At(s, {"seed"}))});
  t.Row({"flat dot sheet", Text(At(s, {"flat_sheet"}))});
  if (!At(s, {"configuration"}).is_null()) t.Row({"configuration", Text(At(s, {"configuration"}))});
  const json& hidden = At(s, {"hidden_errors"});
  if (hidden.is_object()) {
    for (const auto& [key, value] : hidden.items()) t.Row({"hidden error: " + key, Text(value)});
  }
  if (At(s, {"paper_pipeline_applies"}) != false) {
    t.Row({"identifiable parameters (paper)", Text(At(s, {"identifiable_parameters"}))});
    t.Row({"fixed parameters (paper)", Text(At(s, {"fixed_parameters"}))});
  }
  t.Row({"free parameters (bundle)", Text(At(s, {"bundle_free_parameters"}))});
  t.Row({"fixed parameters (bundle)", Text(At(s, {"bundle_fixed_parameters"}))});
  t.Row({"total time (s)", Text(At(s, {"seconds_total"}))});
  page->Add(t);
}

// paper_rows false (eye-to-hand: the paper pipeline not run): the bundle adjustment's rows only.
void Table2(const json& cells, const json& paper, bool paper_rows, Page* page) {
  page->Heading(2, "Table 2: pose measurement errors (mean \u00b1 SD over pose pairs and runs)", "table2");
  Table t({"cell", "method", "position (mm)", "orientation (1e-4 rad)", "f_x (px)", "runs (failed)"});
  for (const json& c : cells) {
    const std::string runs = Text(At(c, {"runs"})) + " (" + Text(At(c, {"runs_failed"})) + ")";
    const json& b = At(c, {"kinematic_bundle", "relative_pose_identification"});
    auto bundle_row = [&]() {
      if (b.is_null()) return;
      t.Row({Cell(c), "kinematic bundle adjustment", MeanSd(At(b, {"position_mm"})),
             MeanSd(At(b, {"orientation_1e4rad"})), MeanSd(At(b, {"fx_px"})),
             Text(At(c, {"kinematic_bundle", "runs"})) + " (" + Text(At(c, {"kinematic_bundle", "runs_failed"})) + ")"});
    };
    if (!paper_rows) {
      bundle_row();
      continue;
    }
    const json& p = At(c, {"paper_pipeline"});
    t.Row({Cell(c), "paper pipeline", MeanSd(At(p, {"position_mm"})), MeanSd(At(p, {"orientation_1e4rad"})),
           MeanSd(At(p, {"fx_px"})), runs});
    t.Row({Cell(c), "paper pipeline, true scale", MeanSd(At(p, {"position_true_scale_mm"})), "", "", runs});
    const json& o = At(c, {"opencv_true_fx"});
    if (At(o, {"position_mm", "n"}) != 0 && !At(o, {"position_mm"}).is_null()) {
      t.Row({Cell(c), "OpenCV, true f_x", MeanSd(At(o, {"position_mm"})), MeanSd(At(o, {"orientation_1e4rad"})), "", runs});
    }
    const json& u = At(c, {"cramer_rao_fx_unknown"});
    if (At(u, {"position_mm_rms", "n"}) != 0 && !At(u, {"position_mm_rms"}).is_null()) {
      t.Row({Cell(c), "Cramer-Rao bound, f_x unknown (RMS)", Rms(At(u, {"position_mm_rms"})),
             Rms(At(u, {"orientation_1e4rad_rms"})), Rms(At(u, {"fx_px_rms"})), ""});
    }
    bundle_row();
  }
  page->Add(t);
  if (!paper_rows) return;
  Table lit({"trajectory", "noise (px)", "position (mm)", "orientation (1e-4 rad)", "f_x (px)"});
  for (const json& row : paper) {
    auto pair = [&](const char* key) {
      const json& v = At(row, {key});
      return v.is_array() && v.size() == 2 ? Text(v[0]) + " \u00b1 " + Text(v[1]) : Text(v);
    };
    lit.Row({Text(At(row, {"trajectory"})), Text(At(row, {"noise_px"})), pair("position_mm"), pair("orientation_1e4rad"),
             pair("fx_px")});
  }
  if (!lit.empty()) {
    page->Heading(3, "The paper's Table 2 (Meng & Zhuang 2001), for comparison");
    page->Add(lit);
  }
}

void Fig6(const json& cells, Page* page) {
  page->Heading(2, "Fig. 6: 3-D error of the check distances on the verification poses (mm)", "fig6");
  Table t({"cell", "nominal model", "paper pipeline", "bundle adjustment", "bundle: predicted RMS std",
           "bundle: 2-sigma coverage"});
  json traces = json::array();
  std::vector<std::pair<std::string, std::vector<const char*>>> series = {
      {"nominal model", {"fig6_3d_error_mm", "nominal_model"}},
      {"paper pipeline", {"fig6_3d_error_mm", "calibrated"}},
      {"bundle adjustment", {"kinematic_bundle", "fig6_3d_error_mm"}}};
  for (const auto& [name, path] : series) {
    json trace = {{"type", "bar"}, {"name", name}, {"x", json::array()}, {"y", json::array()},
                  {"error_y", {{"type", "data"}, {"array", json::array()}, {"visible", true}}}};
    for (const json& c : cells) {
      const json* stat = &c;
      for (const char* key : path) stat = &At(*stat, {key});
      trace["x"].push_back(html::PlotText(Cell(c)));
      trace["y"].push_back(At(*stat, {"mean"}));
      trace["error_y"]["array"].push_back(At(*stat, {"sd"}));
    }
    traces.push_back(trace);
  }
  for (const json& c : cells) {
    const json& b = At(c, {"kinematic_bundle"});
    t.Row({Cell(c), MeanSd(At(c, {"fig6_3d_error_mm", "nominal_model"})), MeanSd(At(c, {"fig6_3d_error_mm", "calibrated"})),
           MeanSd(At(b, {"fig6_3d_error_mm"})), Rms(At(b, {"predicted_3d_error_mm", "predicted"})),
           Text(At(b, {"coverage_2sigma", "fraction"}))});
  }
  page->Add(t);
  if (!cells.empty()) {
    page->Figure(traces,
                 {{"title", {{"text", "3-D error of the check distances (mean \u00b1 SD, mm)"}}}, {"barmode", "group"},
                  {"height", 420}, {"xaxis", {{"type", "category"}}}, {"yaxis", {{"title", {{"text", "error (mm)"}}}}}},
                 "Per cell (trajectory @ pixel noise): the nominal model, the paper pipeline's and the bundle "
                 "adjustment's calibrated models on the verification poses.");
  }
}

void BoundSweep(const json& sweeps, Page* page) {
  if (!sweeps.is_array() || sweeps.empty()) return;
  page->Heading(2, "Two-view Cramer-Rao bound sweep", "bound-sweep");
  Table t({"noise (px)", "f_x (px)", "fov (deg)", "depth (mm)", "depth spread", "baseline (mm)", "points",
           "position (mm), f_x unknown", "orientation (1e-4 rad), f_x unknown", "f_x RMS (px)"});
  for (const json& sweep : sweeps) {
    for (const json& p : sweep) {
      t.Row({Text(At(p, {"sigma_px"})), Text(At(p, {"fx_px"})), Text(At(p, {"horizontal_fov_deg"})),
             Text(At(p, {"depth_mm"})), Text(At(p, {"depth_spread_ratio"})), Text(At(p, {"baseline_mm"})),
             Text(At(p, {"num_points"})), Text(At(p, {"position_mm_fx_unknown"})),
             Text(At(p, {"orientation_1e4rad_fx_unknown"})), Text(At(p, {"fx_px_rms"}))});
    }
  }
  page->Add(t);
}

void Failures(const json& cells, Page* page) {
  Table t({"cell", "method", "failures"});
  for (const json& c : cells) {
    if (At(c, {"failures"}).is_array() && !At(c, {"failures"}).empty()) {
      t.Row({Cell(c), "paper pipeline", Text(At(c, {"failures"}))}, "fail");
    }
    const json& b = At(c, {"kinematic_bundle", "failures"});
    if (b.is_array() && !b.empty()) t.Row({Cell(c), "bundle adjustment", Text(b)}, "fail");
  }
  if (t.empty()) return;
  page->Heading(2, "Failed runs", "failures");
  page->Add(t);
}

}  // namespace

std::string StudyReportHtml(const json& s, const std::string& plotly_js) {
  Page page("selfcal study report");
  page.Heading(1, "selfcal study: the paper's Table 2 and Fig. 6 on the simulator");
  page.Paragraph("selfcal " + Text(At(s, {"software_version"})) + "; format " + Text(At(s, {"format"})) + " version " +
                     Text(At(s, {"version"})) + ". " + Text(At(s, {"pixel_noise_note"})),
                 "meta");
  if (At(s, {"flat_sheet"}) == true) {
    page.Paragraph("Flat dot sheet: the paper's factor method is degenerate there; its rows count only the runs it "
                   "completed.",
                   "note");
  }
  const bool paper_rows = At(s, {"paper_pipeline_applies"}) != false;
  if (!paper_rows) {
    page.Paragraph("Configuration " + Text(At(s, {"configuration"})) + ": the paper pipeline's rows are left out; it is " +
                       Text(At(s, {"paper_pipeline_note"})),
                   "note");
  }
  SettingsTable(s, &page);
  const json& cells = At(s, {"cells"}).is_array() ? At(s, {"cells"}) : json::array();
  Table2(cells, At(s, {"paper_table2"}).is_array() ? At(s, {"paper_table2"}) : json::array(), paper_rows, &page);
  Fig6(cells, &page);
  BoundSweep(At(s, {"bound_sweep"}), &page);
  Failures(cells, &page);
  return page.Render(plotly_js);
}

}  // namespace selfcal::report
