#include "report/calibration_html_figures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"

namespace selfcal::report::html {

namespace {

using nlohmann::json;

constexpr const char* kIdentificationColour = "#1f77b4";
constexpr const char* kHeldOutColour = "#ff7f0e";
constexpr const char* kNominalColour = "#8c8c8c";
constexpr const char* kDotColour = "#2ca02c";

// A 3-vector from a JSON array of three numbers; false when it is not one.
bool Vector3(const json& v, Eigen::Vector3d* out) {
  if (!v.is_array() || v.size() != 3) return false;
  for (int k = 0; k < 3; ++k) {
    if (!v[k].is_number()) return false;
    (*out)[k] = v[k].get<double>();
  }
  return true;
}

struct Residual {
  std::string pose;
  int dot = -1;
  double u = 0, v = 0, du = 0, dv = 0;
  double norm() const { return std::hypot(du, dv); }
};

// The well-formed rows of a residual list (plot_data.*_residuals); others are skipped.
std::vector<Residual> Residuals(const json& rows) {
  std::vector<Residual> out;
  if (!rows.is_array()) return out;
  for (const json& row : rows) {
    const json& pixel = At(row, {"pixel_px"});
    const json& r = At(row, {"residual_px"});
    if (!pixel.is_array() || pixel.size() != 2 || !r.is_array() || r.size() != 2) continue;
    Residual x;
    x.pose = Text(At(row, {"pose"}));
    x.dot = At(row, {"dot"}).is_number_integer() ? At(row, {"dot"}).get<int>() : -1;
    x.u = Number(pixel[0]);
    x.v = Number(pixel[1]);
    x.du = Number(r[0]);
    x.dv = Number(r[1]);
    if (std::isfinite(x.u) && std::isfinite(x.v) && std::isfinite(x.du) && std::isfinite(x.dv)) out.push_back(x);
  }
  return out;
}

json Axis(const std::string& title) { return {{"title", {{"text", title}}}}; }

// Lines of a scatter trace: each segment (a, b) followed by a gap.
void AddSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, json* trace) {
  for (const char* k : {"x", "y", "z"}) {
    const int i = k[0] - 'x';
    (*trace)[k].push_back(a[i] * kMmPerM);
    (*trace)[k].push_back(b[i] * kMmPerM);
    (*trace)[k].push_back(nullptr);
  }
}

json Scatter3d(const std::string& name, const std::string& mode) {
  return {{"type", "scatter3d"}, {"mode", mode}, {"name", name}, {"x", json::array()}, {"y", json::array()},
          {"z", json::array()}};
}

}  // namespace

void SceneFigure(const json& plot_data, const json& verification, Page* page) {
  std::map<int, Eigen::Vector3d> dots;
  for (const json& d : At(plot_data, {"dots_in_base"})) {
    Eigen::Vector3d p;
    if (At(d, {"dot"}).is_number_integer() && Vector3(At(d, {"xyz_m"}), &p)) dots[At(d, {"dot"}).get<int>()] = p;
  }
  json dot_trace = Scatter3d("dots (bundle)", "markers");
  dot_trace["marker"] = {{"size", 3}, {"color", kDotColour}};
  dot_trace["text"] = json::array();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& [id, p] : dots) {
    for (int k = 0; k < 3; ++k) dot_trace[std::string(1, char('x' + k))].push_back(p[k] * kMmPerM);
    dot_trace["text"].push_back("dot " + std::to_string(id));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  struct Camera {
    std::string pose, role;
    Rigid3 base_from_cam;
  };
  std::vector<Camera> cameras;
  for (const json& c : At(plot_data, {"camera_poses_from_model"})) {
    Eigen::Vector3d t, w;
    if (!Vector3(At(c, {"xyz_m"}), &t) || !Vector3(At(c, {"rotvec_rad"}), &w)) continue;
    cameras.push_back({Text(At(c, {"pose"})), Text(At(c, {"role"})), Rigid3(ExpSO3<double>(w), t)});
    lo = lo.cwiseMin(t);
    hi = hi.cwiseMax(t);
  }
  if (cameras.empty()) {
    page->Paragraph("No camera poses in this report (the bundle adjustment stopped before solving): no 3-D view.",
                    "note");
    return;
  }
  const double axis_m = std::max(0.12 * (hi - lo).maxCoeff(), 0.01);
  json data = json::array();
  data.push_back(dot_trace);
  for (const std::string role : {"identification", "verification"}) {
    json centres = Scatter3d(role + " cameras", "markers");
    json axes = Scatter3d(role + " optical axes", "lines");
    const char* colour = role == "identification" ? kIdentificationColour : kHeldOutColour;
    centres["marker"] = {{"size", 4}, {"color", colour}, {"symbol", "diamond"}};
    centres["text"] = json::array();
    axes["line"] = {{"color", colour}, {"width", 3}};
    axes["showlegend"] = false;
    for (const Camera& c : cameras) {
      if (c.role != role) continue;
      const Eigen::Vector3d& t = c.base_from_cam.translation;
      for (int k = 0; k < 3; ++k) centres[std::string(1, char('x' + k))].push_back(t[k] * kMmPerM);
      centres["text"].push_back(PlotText("pose " + c.pose));
      AddSegment(t, t + axis_m * c.base_from_cam.rotation.col(2), &axes);
    }
    if (centres["text"].empty()) continue;
    data.push_back(centres);
    data.push_back(axes);
  }
  json checks = Scatter3d("check distances", "lines");
  checks["line"] = {{"color", "#555555"}, {"width", 2}, {"dash", "dot"}};
  for (const json& c : At(verification, {"calibrated_model", "checks"})) {
    const json& a = At(c, {"dot_a"});
    const json& b = At(c, {"dot_b"});
    if (!a.is_number_integer() || !b.is_number_integer()) continue;
    const auto pa = dots.find(a.get<int>()), pb = dots.find(b.get<int>());
    if (pa != dots.end() && pb != dots.end()) AddSegment(pa->second, pb->second, &checks);
  }
  if (!checks["x"].empty()) data.push_back(checks);
  const char* colours[3] = {"#d62728", "#2ca02c", "#1f77b4"};
  for (int k = 0; k < 3; ++k) {
    json axis = Scatter3d(std::string("base ") + char('x' + k), "lines");
    axis["line"] = {{"color", colours[k]}, {"width", 6}};
    AddSegment(Eigen::Vector3d::Zero(), axis_m * Eigen::Vector3d::Unit(k), &axis);
    data.push_back(axis);
  }
  json layout = {{"title", {{"text", "Cameras and dots in the base frame (calibrated model)"}}},
                 {"height", 620},
                 {"margin", {{"t", 50}, {"l", 0}, {"r", 0}, {"b", 0}}},
                 {"scene", {{"aspectmode", "data"}, {"xaxis", Axis("x (mm)")}, {"yaxis", Axis("y (mm)")},
                            {"zaxis", Axis("z (mm)")},
                            {"camera", {{"eye", {{"x", 1.7}, {"y", 1.7}, {"z", 1.1}}}}}}}};
  page->Figure(data, layout,
               "Each camera's centre and optical axis (z) where the calibrated model puts it; the dots as the bundle "
               "adjustment placed them; dotted: the known check distances; red, green, blue: the base frame's x, y, z. "
               "Drag to rotate.");
}

void ResidualFigures(const json& plot_data, double noise_px, Page* page) {
  const std::vector<Residual> fit = Residuals(At(plot_data, {"identification_residuals"}));
  const std::vector<Residual> heldout = Residuals(At(plot_data, {"heldout_residuals"}));
  if (fit.empty() && heldout.empty()) {
    page->Paragraph("No per-observation residuals in this report (the bundle adjustment stopped before solving).",
                    "note");
    return;
  }
  struct Set {
    const std::vector<Residual>* residuals;
    std::string name;
    const char* colour;
  };
  const Set sets[2] = {{&fit, "identification (fit)", kIdentificationColour},
                       {&heldout, "held-out (verification)", kHeldOutColour}};
  json histogram = json::array(), boxes = json::array(), image = json::array();
  double largest = 0;
  std::vector<double> norms;
  for (const Set& s : sets) {
    if (s.residuals->empty()) continue;
    json h = {{"type", "histogram"}, {"name", s.name}, {"x", json::array()}, {"histnorm", "probability density"},
              {"opacity", 0.6}, {"marker", {{"color", s.colour}}}};
    json b = {{"type", "box"}, {"name", s.name}, {"x", json::array()}, {"y", json::array()},
              {"marker", {{"color", s.colour}, {"size", 3}}}, {"boxpoints", "outliers"}};
    for (const Residual& r : *s.residuals) {
      h["x"].push_back(r.norm());
      b["x"].push_back(PlotText(r.pose));
      b["y"].push_back(r.norm());
      largest = std::max(largest, r.norm());
      norms.push_back(r.norm());
    }
    histogram.push_back(h);
    boxes.push_back(b);
  }
  if (std::isfinite(noise_px) && noise_px > 0) {
    // |r| of a 2-D residual with std sigma per coordinate: Rayleigh, r / sigma^2 exp(-r^2 / 2 sigma^2).
    json curve = {{"type", "scatter"}, {"mode", "lines"}, {"name", "correct model at the noise"},
                  {"x", json::array()}, {"y", json::array()}, {"line", {{"color", "#000000"}, {"dash", "dash"}}}};
    const double top = std::max(largest, 4 * noise_px);
    for (int k = 0; k <= 200; ++k) {
      const double r = top * k / 200.0;
      curve["x"].push_back(r);
      curve["y"].push_back(r / (noise_px * noise_px) * std::exp(-r * r / (2 * noise_px * noise_px)));
    }
    histogram.push_back(curve);
  }
  page->Figure(histogram,
               {{"title", {{"text", "Reprojection error |r| (px)"}}}, {"barmode", "overlay"}, {"height", 400},
                {"xaxis", Axis("|detection - prediction| (px)")}, {"yaxis", Axis("density (1/px)")}},
               "Histogram of the 2-D reprojection error of every detection; dashed: its density for a correct model "
               "at the pixel noise of the normalisation (" + Format(noise_px) + " px per coordinate).");
  page->Figure(boxes,
               {{"title", {{"text", "Reprojection error per pose (px)"}}}, {"boxmode", "group"}, {"height", 420},
                {"xaxis", {{"title", {{"text", "pose"}}}, {"type", "category"}}}, {"yaxis", Axis("|r| (px)")}},
               "One box per pose: median, quartiles and outliers of |r| over its dots.");
  std::sort(norms.begin(), norms.end());
  const double p95 = norms.empty() ? 0 : norms[std::min(norms.size() - 1, norms.size() * 95 / 100)];
  const double width = Number(At(plot_data, {"image", "width_px"}));
  const double height = Number(At(plot_data, {"image", "height_px"}));
  const double scale = p95 > 0 && width > 0 ? std::max(1.0, std::round(0.04 * width / p95)) : 1.0;
  for (const Set& s : sets) {
    if (s.residuals->empty()) continue;
    json points = {{"type", "scatter"}, {"mode", "markers"}, {"name", s.name}, {"x", json::array()},
                   {"y", json::array()}, {"text", json::array()},
                   {"marker", {{"size", 5}, {"color", s.colour}}}};
    json vectors = {{"type", "scatter"}, {"mode", "lines"}, {"name", s.name + ", residual x " + Format(scale, 3)},
                    {"x", json::array()}, {"y", json::array()}, {"line", {{"color", s.colour}, {"width", 1}}}};
    for (const Residual& r : *s.residuals) {
      points["x"].push_back(r.u);
      points["y"].push_back(r.v);
      points["text"].push_back(PlotText("pose " + r.pose + ", dot " + std::to_string(r.dot) + ": |r| " +
                                        Format(r.norm(), 3) + " px"));
      for (const auto& [a, b] : {std::pair{r.u, r.v}, {r.u - scale * r.du, r.v - scale * r.dv}}) {
        vectors["x"].push_back(a);
        vectors["y"].push_back(b);
      }
      vectors["x"].push_back(nullptr);
      vectors["y"].push_back(nullptr);
    }
    image.push_back(vectors);
    image.push_back(points);
  }
  json xaxis = Axis("u (px)"), yaxis = Axis("v (px)");
  json layout = {{"title", {{"text", "Residuals over the image"}}}, {"height", 560}};
  if (width > 0 && height > 0) {
    xaxis["range"] = {0, width};
    yaxis["range"] = {height, 0};  // v down, as in the image
    // Square pixels: the plot area shrinks to the image's aspect rather than the ranges growing.
    xaxis["constrain"] = yaxis["constrain"] = "domain";
    layout["shapes"] = json::array({{{"type", "rect"}, {"x0", 0}, {"x1", width}, {"y0", 0}, {"y1", height},
                                     {"line", {{"color", "#555555"}, {"width", 1}}}}});
  } else {
    yaxis["autorange"] = "reversed";
  }
  yaxis["scaleanchor"] = "x";
  layout["xaxis"] = xaxis;
  layout["yaxis"] = yaxis;
  page->Figure(image, layout,
               "Each detection (dot) and, from it, the prediction's offset (prediction - detection) magnified " +
                   Format(scale, 3) + " times; all poses superimposed in the image's own coordinates.");
}

void CorrectionFigure(const json& parameters, Page* page) {
  json lengths = {{"type", "scatter"}, {"mode", "markers"}, {"name", "length (mm)"}, {"x", json::array()},
                  {"y", json::array()}, {"error_y", {{"type", "data"}, {"array", json::array()}, {"visible", true}}},
                  {"marker", {{"color", kIdentificationColour}, {"size", 7}}}, {"xaxis", "x"}, {"yaxis", "y"}};
  json angles = lengths;
  angles["name"] = "angle (deg)";
  angles["marker"]["color"] = kHeldOutColour;
  angles["xaxis"] = "x2";
  angles["yaxis"] = "y2";
  if (parameters.is_array()) {
    for (const json& row : parameters) {
      if (At(row, {"free"}) != true) continue;
      const bool length = At(row, {"correction_m"}).is_number();
      const double value = Number(At(row, {length ? "correction_m" : "correction_rad"}));
      const double sd = Number(At(row, {length ? "stddev_m" : "stddev_rad"}));
      if (!std::isfinite(value)) continue;
      json& trace = length ? lengths : angles;
      const double unit = length ? kMmPerM : RadToDeg(1.0);
      trace["x"].push_back(PlotText(Text(At(row, {"name"}))));
      trace["y"].push_back(value * unit);
      trace["error_y"]["array"].push_back(std::isfinite(sd) ? json(sd * unit) : json(nullptr));
    }
  }
  if (lengths["x"].empty() && angles["x"].empty()) {
    page->Paragraph("No free parameter has a correction in this report.", "note");
    return;
  }
  json layout = {{"title", {{"text", "Corrections of the free parameters (value - nominal) with +-1 sigma"}}},
                 {"height", 440},
                 {"grid", {{"rows", 1}, {"columns", 2}, {"pattern", "independent"}}},
                 {"xaxis", {{"type", "category"}, {"tickangle", -60}}},
                 {"yaxis", Axis("length correction (mm)")},
                 {"xaxis2", {{"type", "category"}, {"tickangle", -60}}},
                 {"yaxis2", Axis("angle correction (deg)")},
                 {"margin", {{"t", 50}, {"l", 70}, {"r", 30}, {"b", 110}}}};
  page->Figure(json::array({lengths, angles}), layout,
               "Left: lengths (mm); right: angles (degrees). Bars: the bundle's marginal standard deviation. Fixed "
               "parameters (gauge, unidentifiable, held) are in the table below, not here.");
}

void CorrelationFigure(const json& plot_data, Page* page) {
  const json& names = At(plot_data, {"correlation", "names"});
  const json& matrix = At(plot_data, {"correlation", "matrix"});
  if (!names.is_array() || !matrix.is_array() || names.empty() || matrix.size() != names.size()) {
    page->Paragraph("No correlation matrix in this report (no covariance).", "note");
    return;
  }
  json labels = json::array();
  for (const json& n : names) labels.push_back(PlotText(Text(n)));
  json trace = {{"type", "heatmap"}, {"x", labels}, {"y", labels}, {"z", matrix}, {"zmin", -1}, {"zmax", 1},
                {"colorscale", "RdBu"}, {"reversescale", true}};
  json layout = {{"title", {{"text", "Correlations of the estimated parameters"}}},
                 {"height", std::max(420, 18 * static_cast<int>(names.size()) + 160)},
                 {"xaxis", {{"type", "category"}, {"tickangle", -60}}},
                 {"yaxis", {{"type", "category"}, {"autorange", "reversed"}}},
                 {"margin", {{"t", 50}, {"l", 90}, {"r", 30}, {"b", 100}}}};
  page->Figure(json::array({trace}), layout,
               "Near +-1: two parameters the images barely tell apart (weakly identifiable combinations).");
}

void HeldOutFigure(const json& heldout, Page* page) {
  json traces = json::array();
  json ratio = {{"type", "bar"}, {"name", "calibrated: chi-square / 95 % limit"}, {"x", json::array()},
                {"y", json::array()}, {"marker", {{"color", kHeldOutColour}}}};
  for (const auto& [key, name, colour] : {std::tuple{"calibrated_model", "calibrated model", kHeldOutColour},
                                          {"nominal_model", "nominal model", kNominalColour}}) {
    json bars = {{"type", "bar"}, {"name", name}, {"x", json::array()}, {"y", json::array()},
                 {"marker", {{"color", colour}}}};
    for (const json& pose : At(heldout, {key, "poses"})) {
      bars["x"].push_back(PlotText(Text(At(pose, {"pose"}))));
      bars["y"].push_back(At(pose, {"rms_px"}));
      if (std::string(key) == "calibrated_model") {
        const double limit = Number(At(pose, {"chi_square_limit"}));
        ratio["x"].push_back(PlotText(Text(At(pose, {"pose"}))));
        ratio["y"].push_back(limit > 0 ? json(Number(At(pose, {"chi_square"})) / limit) : json(nullptr));
      }
    }
    if (!bars["x"].empty()) traces.push_back(bars);
  }
  if (traces.empty()) {
    page->Paragraph("No held-out reprojection figures per pose in this report.", "note");
    return;
  }
  const double noise = Number(At(heldout, {"noise_px"}));
  // The log axis's range (in log10 units) from below the noise to above the largest RMS.
  double low = std::isfinite(noise) ? noise : INFINITY, high = 0;
  for (const json& trace : traces) {
    for (const json& y : trace["y"]) {
      const double v = Number(y);
      if (v > 0) low = std::min(low, v), high = std::max(high, v);
    }
  }
  json layout = {{"title", {{"text", "Held-out reprojection RMS per verification pose (px)"}}}, {"barmode", "group"},
                 {"height", 400}, {"xaxis", {{"title", {{"text", "verification pose"}}}, {"type", "category"}}},
                 {"yaxis", {{"title", {{"text", "RMS per coordinate (px, log scale)"}}}, {"type", "log"}}}};
  if (high > 0 && std::isfinite(low)) layout["yaxis"]["range"] = {std::log10(low / 1.5), std::log10(high * 1.3)};
  if (std::isfinite(noise)) {
    // A shape's y is in data units, on a log axis too (unlike the axis range).
    layout["shapes"] = json::array({{{"type", "line"}, {"xref", "paper"}, {"x0", 0}, {"x1", 1}, {"y0", noise},
                                     {"y1", noise}, {"line", {{"color", "#000000"}, {"dash", "dash"}}}}});
  }
  page->Figure(traces, layout,
               "The identification images' dots projected into each verification image; dashed: the pixel noise of "
               "the normalisation (" + Format(noise) + " px). A correct model's RMS sits near it, beside the prediction's "
               "own uncertainty.");
  json ratio_layout = {{"title", {{"text", "Held-out chi-square per verification pose at the estimated noise (a figure, not "
                                           "the verdict's test)"}}},
                       {"height", 360}, {"xaxis", {{"title", {{"text", "verification pose"}}}, {"type", "category"}}},
                       {"yaxis", Axis("chi-square / 95 % limit")},
                       {"shapes", json::array({{{"type", "line"}, {"xref", "paper"}, {"x0", 0}, {"x1", 1}, {"y0", 1},
                                                {"y1", 1}, {"line", {{"color", "#c62828"}, {"dash", "dash"}}}}})}};
  page->Figure(json::array({ratio}), ratio_layout,
               "Each pose's chi-square over its own 95 % limit, normalised with the bundle's noise estimate ("
               + Format(noise) + " px): at 95 % one pose in twenty of a correct model lies above the dashed line at 1. "
               "The verdict's test is the table's.");
}

void CheckDistanceFigure(const json& verification, const json& predicted, Page* page) {
  std::map<std::pair<int, int>, double> predicted_std;
  for (const json& d : At(predicted, {"distances"})) {
    if (At(d, {"dot_a"}).is_number_integer() && At(d, {"dot_b"}).is_number_integer()) {
      predicted_std[{At(d, {"dot_a"}).get<int>(), At(d, {"dot_b"}).get<int>()}] = Number(At(d, {"std_m"}));
    }
  }
  json traces = json::array();
  for (const auto& [key, name, colour] : {std::tuple{"nominal_model", "nominal model", kNominalColour},
                                          {"calibrated_model", "calibrated model", kHeldOutColour}}) {
    json bars = {{"type", "bar"}, {"name", name}, {"x", json::array()}, {"y", json::array()},
                 {"marker", {{"color", colour}}}};
    json errors = json::array();
    for (const json& c : At(verification, {key, "checks"})) {
      const json& a = At(c, {"dot_a"});
      const json& b = At(c, {"dot_b"});
      bars["x"].push_back(PlotText(Text(a) + "-" + Text(b)));
      bars["y"].push_back(Number(At(c, {"error_m"})) * kMmPerM);
      const auto p = a.is_number_integer() && b.is_number_integer() ? predicted_std.find({a.get<int>(), b.get<int>()})
                                                                     : predicted_std.end();
      errors.push_back(p != predicted_std.end() && std::isfinite(p->second) ? json(p->second * kMmPerM) : json(nullptr));
    }
    if (std::string(key) == "calibrated_model" && !predicted_std.empty()) {
      bars["error_y"] = {{"type", "data"}, {"array", errors}, {"visible", true}};
    }
    if (!bars["x"].empty()) traces.push_back(bars);
  }
  if (traces.empty()) {
    page->Paragraph("No check distances in this report: the held-out reprojection above is the verification.", "note");
    return;
  }
  page->Figure(traces,
               {{"title", {{"text", "3-D error of the known check distances (mm)"}}}, {"barmode", "group"},
                {"height", 420}, {"xaxis", {{"title", {{"text", "dots"}}}, {"type", "category"}, {"tickangle", -60}}},
                {"yaxis", Axis("|measured - known| (mm)")}},
               "Each known distance triangulated from the verification images with either model; error bars on the "
               "calibrated model: its predicted std (first order).");
}

}  // namespace selfcal::report::html
