// The calibration page of report.html (html_report.h), section by section from a report.json document.
#include <cmath>
#include <string>
#include <vector>

#include "geometry/rigid3.h"
#include "report/calibration_html_figures.h"
#include "report/calibration_report.h"
#include "report/html_report.h"
#include "report/html_writer.h"

namespace selfcal::report {

namespace {

using html::At;
using html::Format;
using html::Number;
using html::Page;
using html::Table;
using html::Text;
using nlohmann::json;

constexpr double kDeg = RadToDeg(1.0);

std::string Mm(const json& v) { return Text(v, 4, kMmPerM); }
std::string Yes(const json& v) { return v.is_boolean() ? (v.get<bool>() ? "yes" : "no") : Text(v); }

// The reasons of a verdict, in whatever form the document gives them: strings, or objects with a
// message (and perhaps a code).
std::vector<std::string> Reasons(const json& reasons) {
  std::vector<std::string> out;
  if (!reasons.is_array()) return out;
  for (const json& r : reasons) {
    if (r.is_string()) {
      out.push_back(r.get<std::string>());
    } else if (r.is_object()) {
      std::string text;
      for (const char* key : {"message", "reason", "text"}) {
        if (At(r, {key}).is_string()) text = At(r, {key}).get<std::string>();
      }
      const json& code = At(r, {"code"});
      if (text.empty()) text = r.dump(-1, ' ', false, json::error_handler_t::replace);
      out.push_back(code.is_string() ? code.get<std::string>() + ": " + text : text);
    }
  }
  return out;
}

// The verdict first: the word, the message, the reasons, the exit code; then the key figures.
void VerdictSection(const json& r, Page* page) {
  const bool accepted = At(r, {"accepted"}) == true;
  const std::string verdict = Text(At(r, {"verdict"}));
  const bool untested = verdict == "untested";  // a model written, that no held-out test verified
  std::string box = std::string("<div class=\"verdict ") + (accepted ? "ok" : untested ? "untested" : "refused") +
                    "\" id=\"verdict\">";
  box += "<div class=\"word\">" +
         html::EscapeHtml(accepted ? "Accepted" : untested ? "Untested" : "Not accepted (" + verdict + ")") + "</div>";
  const std::string message = Text(At(r, {"message"}));
  const std::vector<std::string> reasons = Reasons(At(r, {"reasons"}));
  // A refusal's message is its reasons joined: the list says it once.
  if (!reasons.empty()) {
    box += "<p>The calibrated model is refused:</p>";
  } else if (!message.empty() && message != "\u2014") {
    box += "<p>" + html::EscapeHtml(message) + "</p>";
  }
  if (!reasons.empty()) {
    box += "<ul>";
    for (const std::string& reason : reasons) box += "<li>" + html::EscapeHtml(reason) + "</li>";
    box += "</ul>";
  }
  box += "<p>" + html::EscapeHtml("exit code " + Text(At(r, {"exit_code"})) + "; method " + Text(At(r, {"method"})) +
                                  (accepted   ? "; the calibrated model was written"
                                   : untested ? "; the calibrated model was written, not verified by a held-out test"
                                              : "; no calibrated model was written")) +
         "</p></div>\n";
  page->Markup(box);
  const json& checks = At(r, {"acceptance"});
  if (checks.is_array() && !checks.empty()) {
    Table a({"acceptance check", "status", "what it found"});
    for (const json& c : checks) {
      const std::string status = Text(At(c, {"status"})) + (At(c, {"decisive"}) == false ? " (figure only)" : "");
      a.Row({Text(At(c, {"check"})), status, Text(At(c, {"sentence"}))},
            At(c, {"status"}) == "failed" && At(c, {"decisive"}) != false ? "fail" : "");
    }
    page->Markup(a.Html());
  }

  const json& heldout = At(r, {"heldout_reprojection"});
  const json& verification = At(r, {"verification"});
  Table t({"figure", accepted ? "calibrated model" : "result (not accepted)", "nominal model"});
  t.Row({"configuration (camera on the flange: eye_in_hand; fixed: eye_to_hand)", Text(At(r, {"configuration"})), ""});
  t.Row({"f_x (px)", Text(At(r, {"fx_px"}), 7), ""});
  const json& bundle = At(r, {"methods", "bundle"});
  t.Row({"fit: reprojection RMS (px)",
         Number(At(bundle, {"num_observations"})) > 0 ? Text(At(bundle, {"rms_reprojection_px"})) : "\u2014", ""});
  t.Row({"held-out reprojection RMS (px)", Text(At(heldout, {"calibrated_model", "overall", "rms_px"})),
         Text(At(heldout, {"nominal_model", "overall", "rms_px"}))});
  t.Row({"held-out chi-square test at 95 % passed (stated noise)", Yes(At(heldout, {"test_passed"})),
         Yes(At(heldout, {"nominal_model", "overall", "test_passed"}))},
        At(heldout, {"test_passed"}) == false ? "fail" : "");
  t.Row({"held-out: calibrated beats nominal", Yes(At(heldout, {"beats_nominal"})), ""},
        At(heldout, {"beats_nominal"}) == false ? "fail" : "");
  t.Row({"check distances: RMS 3-D error (mm)", Mm(At(verification, {"calibrated_model", "rms_error_m"})),
         Mm(At(verification, {"nominal_model", "rms_error_m"}))});
  t.Row({"check distances: max 3-D error (mm)", Mm(At(verification, {"calibrated_model", "max_error_m"})),
         Mm(At(verification, {"nominal_model", "max_error_m"}))});
  t.Row({"stated pixel noise (px)", Text(At(r, {"pixel_noise_px"})), ""});
  page->Add(t);
}

void ResidualSection(const json& r, Page* page) {
  page->Heading(2, "Reprojection residuals", "residuals");
  const json& b = At(r, {"methods", "bundle"});
  if (b.is_null()) {
    page->Paragraph("The bundle adjustment did not run (method " + Text(At(r, {"method"})) +
                        "): the paper's pipeline has no reprojection residuals.",
                    "note");
    return;
  }
  Table t({"observations in the fit", "RMS (px)", "removed by the screen", "dots seen once (dropped)",
           "solver termination"});
  t.Row({Text(At(b, {"num_observations"})), Text(At(b, {"rms_reprojection_px"})),
         std::to_string(At(b, {"removed_observations"}).size()), std::to_string(At(b, {"dropped_dots"}).size()),
         Text(At(b, {"solver", "termination"}))});
  page->Add(t);
  double noise = Number(At(r, {"heldout_reprojection", "noise_px"}));
  if (!std::isfinite(noise)) noise = Number(At(r, {"pixel_noise_px"}));
  html::ResidualFigures(At(b, {"plot_data"}), noise, page);
  const json& removed = At(b, {"removed_observations"});
  if (removed.is_array() && !removed.empty()) {
    Table rt({"pose", "dot", "|r| at the solution (px)"});
    for (const json& o : removed) rt.Row({Text(At(o, {"pose"})), Text(At(o, {"dot"})), Text(At(o, {"residual_px"}))});
    page->Heading(3, "Observations removed by the residual screen");
    page->Add(rt);
  }
}

// One row per kinematic parameter, in mm or degrees by its kind (the keys' _m or _rad).
void ParameterTable(const json& parameters, Page* page) {
  const bool paper = parameters.is_array() && !parameters.empty() &&
                     (At(parameters[0], {"identified_before_yardstick_m"}).is_number() ||
                      At(parameters[0], {"identified_before_yardstick_rad"}).is_number());
  const std::string value_key = paper ? "identified_before_yardstick" : "value";
  std::vector<std::string> header = {"parameter", "free", "unit", "nominal",
                                      paper ? "identified (before the yardstick)" : "calibrated", "sigma"};
  if (!paper) header.insert(header.end() - 1, "correction");
  Table t(header);
  if (!parameters.is_array()) return;
  for (const json& row : parameters) {
    const bool length = At(row, {"nominal_m"}).is_number();
    const char* unit = length ? "_m" : "_rad";
    const double scale = length ? kMmPerM : kDeg;
    auto cell = [&](const std::string& key, int digits) { return Text(At(row, {(key + unit).c_str()}), digits, scale); };
    const bool free = At(row, {"free"}) == true;
    std::vector<std::string> cells = {Text(At(row, {"name"})), Yes(At(row, {"free"})), length ? "mm" : "deg",
                                      cell("nominal", 7), cell(value_key, 7), cell("stddev", 3)};
    if (!paper) cells.insert(cells.end() - 1, cell("correction", 4));
    t.Row(cells, free ? "" : "fixed");
  }
  page->Add(t);
}

void ParameterSection(const json& r, Page* page) {
  page->Heading(2, "Parameter corrections", "parameters");
  const std::string method = Text(At(r, {"method"}));
  const json& section = At(r, {"methods", method.c_str()});
  const json& parameters = At(section, {"parameters"});
  if (At(r, {"accepted"}) != true) {
    page->Paragraph("Not accepted: these values are where the solve stopped (or its start), not a model to apply.",
                    "note");
  }
  if (method == "bundle") html::CorrectionFigure(parameters, page);
  Table intrinsics({"intrinsic", "value", "sigma"});
  intrinsics.Row({"f_x (px)", Text(At(section, {"fx_px"}), 7), Text(At(section, {"fx_stddev_px"}), 3)});
  if (!At(section, {"k1"}).is_null()) intrinsics.Row({"k1", Text(At(section, {"k1"})), Text(At(section, {"k1_stddev"}), 3)});
  page->Add(intrinsics);
  ParameterTable(parameters, page);
}

void IdentifiabilitySection(const json& r, Page* page) {
  page->Heading(2, "Identifiability", "identifiability");
  const json& b = At(r, {"methods", "bundle"});
  const json& p = At(r, {"methods", "paper", "identifiability"});
  Table t({"analysis", "free", "fixed", "generic rank", "condition number"});
  if (!b.is_null()) {
    t.Row({"bundle adjustment (reprojection, dots eliminated)", std::to_string(At(b, {"free"}).size()),
           std::to_string(At(b, {"fixed"}).size()), Text(At(b, {"generic_rank"})), Text(At(b, {"condition_number"}))});
  }
  if (!p.is_null()) {
    t.Row({"paper pipeline (relative poses)", Text(At(p, {"identifiable"})), std::to_string(At(p, {"fixed"}).size()),
           "", Text(At(p, {"condition_number"}))});
  }
  page->Add(t);
  const json& section = b.is_null() ? p : b;
  page->Paragraph("Fixed (" + std::string(b.is_null() ? "paper pipeline" : "bundle adjustment") +
                  "): " + Text(At(section, {"fixed"})));
  const json& nulls = At(section, {"null_combinations"});
  std::vector<std::string> combinations;
  if (nulls.is_array()) {
    for (const json& n : nulls) combinations.push_back(Text(n));
  }
  if (!combinations.empty()) {
    page->Paragraph("Combinations the measurements cannot see (the null space, fixed at nominal):");
    page->Bullets(combinations);
  }
  if (!b.is_null()) {
    page->Paragraph("Covariance: " + std::string(At(b, {"covariance_available"}) == true ? "available" : "unavailable") +
                    (Text(At(b, {"covariance_message"})).empty() ? "" : " (" + Text(At(b, {"covariance_message"})) + ")"));
    html::CorrelationFigure(At(b, {"plot_data"}), page);
  }
}

// One held-out test on the page, the verdict's: the calibrated model's chi-square normalised with the stated
// noise (overall_at_stated_noise; a report without it, its overall). The nominal model's row gives its
// errors only: its chi-square is normalised with the bundle's noise estimate, another test.
void HeldOutTable(const json& heldout, Page* page) {
  Table t({"model", "poses", "dots predicted", "RMS (px)", "max (px)", "chi-square", "dof", "95 % limit", "p-value",
           "passed"});
  const json& calibrated = At(heldout, {"calibrated_model"});
  const json& stated = At(calibrated, {"overall_at_stated_noise"});
  const json& o = stated.is_object() ? stated : At(calibrated, {"overall"});
  t.Row({"calibrated (the verdict's test)", std::to_string(At(calibrated, {"poses"}).size()),
         Text(At(o, {"num_residuals"})), Text(At(o, {"rms_px"})), Text(At(o, {"max_px"})), Text(At(o, {"chi_square"}), 5),
         Text(At(o, {"dof"})), Text(At(o, {"chi_square_limit"}), 5), Text(At(o, {"p_value"}), 3),
         Yes(At(o, {"test_passed"}))},
        At(o, {"test_passed"}) == true ? "pass" : At(o, {"test_passed"}) == false ? "fail" : "");
  const json& nominal = At(heldout, {"nominal_model"});
  const json& n = At(nominal, {"overall"});
  t.Row({"nominal (errors only)", std::to_string(At(nominal, {"poses"}).size()), Text(At(n, {"num_residuals"})),
         Text(At(n, {"rms_px"})), Text(At(n, {"max_px"})), "\u2014", "\u2014", "\u2014", "\u2014", "\u2014"});
  page->Add(t);
  page->Paragraph("The test: the chi-square of the calibrated model's held-out residuals normalised with the stated "
                  "pixel noise, " + Text(At(heldout, {"stated_noise_px"})) +
                      " px, the prediction's uncertainty and the pose error the bundle estimated, at 95 %. The bundle's "
                      "own noise estimate (" + Text(At(heldout, {"noise_px"})) + " px, " +
                      Text(At(heldout, {"noise_source"})) + ") scales the per-pose figure below.",
                  "note");
  for (const char* key : {"calibrated_model", "nominal_model"}) {
    const std::string message = Text(At(heldout, {key, "message"}));
    if (!message.empty() && message != "\u2014") page->Paragraph(std::string(key) + ": " + message, "note");
  }
}

void CheckTable(const json& verification, Page* page) {
  Table t({"dots", "known (mm)", "nominal: error (mm)", "calibrated: measured (mm)", "calibrated: error (mm)"});
  const json& nominal = At(verification, {"nominal_model", "checks"});
  const json& calibrated = At(verification, {"calibrated_model", "checks"});
  if (!calibrated.is_array()) return;
  for (size_t k = 0; k < calibrated.size(); ++k) {
    const json& c = calibrated[k];
    const json& n = nominal.is_array() && k < nominal.size() ? nominal[k] : json();
    t.Row({Text(At(c, {"dot_a"})) + "-" + Text(At(c, {"dot_b"})), Mm(At(c, {"known_m"})), Mm(At(n, {"error_m"})),
           Mm(At(c, {"measured_m"})), Mm(At(c, {"error_m"}))},
          At(c, {"ok"}) == false ? "fail" : "");
  }
  if (!t.empty()) page->Add(t);
}

void HeldOutSection(const json& r, Page* page) {
  page->Heading(2, "Held-out verification", "heldout");
  const json& heldout = At(r, {"heldout_reprojection"});
  page->Heading(3, "Reprojection into the verification images");
  if (heldout.is_null()) {
    page->Paragraph("Not computed (method " + Text(At(r, {"method"})) + ", or no model, or no verification pose).",
                    "note");
  } else {
    HeldOutTable(heldout, page);
    html::HeldOutFigure(heldout, page);
  }
  page->Heading(3, "Known check distances");
  const json& verification = At(r, {"verification"});
  page->Paragraph(Text(At(verification, {"calibrated_model", "num_ok"})) + " of " +
                  Text(At(verification, {"calibrated_model", "num_checks"})) + " check distances measured over " +
                  Text(At(verification, {"poses"})) + " verification poses.");
  CheckTable(verification, page);
  const json& predicted = At(r, {"predicted_3d_error"});
  if (At(predicted, {"ok"}) == true) {
    page->Paragraph("Predicted RMS std of the 3-D error: " + Mm(At(predicted, {"rms_std_m"})) + " mm (parameters " +
                    Mm(At(predicted, {"rms_parameters_std_m"})) + " mm, pixels " +
                    Mm(At(predicted, {"rms_pixels_std_m"})) + " mm).");
  }
  html::CheckDistanceFigure(verification, predicted, page);
}

void PaperSection(const json& r, Page* page) {
  const json& p = At(r, {"methods", "paper"});
  if (p.is_null()) return;
  page->Heading(2, "Paper pipeline (Meng & Zhuang 2001)", "paper");
  const std::string message = At(p, {"message"}).is_string() ? At(p, {"message"}).get<std::string>() : "";
  page->Paragraph("Verdict " + Text(At(p, {"verdict"})) + " (" + Text(At(p, {"outcome"})) + ")" +
                  (message.empty() ? "." : ": " + message));
  Table t({"pose", "two-view outcome", "used", "f_x (px)", "inliers", "epipolar RMS (px)", "eq. (21) scale (mm)"});
  for (const json& m : At(p, {"pose_measurements"})) {
    t.Row({Text(At(m, {"pose"})), Text(At(m, {"outcome"})), Yes(At(m, {"used"})), Text(At(m, {"fx_px"}), 6),
           Text(At(m, {"inliers"})), Text(At(m, {"rms_epipolar_px"})), Mm(At(m, {"eq21_scale_m"}))},
          At(m, {"used"}) == false ? "fixed" : "");
  }
  if (!t.empty()) page->Add(t);
  if (Text(At(r, {"method"})) == "paper") return;
  page->Paragraph("Its parameters (the bundle adjustment's start):", "note");
  ParameterTable(At(p, {"parameters"}), page);
}

void ContextSection(const json& r, Page* page) {
  const json& hand_eye = At(r, {"hand_eye"});
  if (!hand_eye.is_null()) {
    // The calibrated camera transform: the fixed camera's in eye-to-hand, else the hand-eye one.
    const std::string name = At(r, {"configuration"}) == "eye_to_hand" ? "base_from_cam" : "flange_from_cam";
    const char* key = name.c_str();
    page->Heading(2, "Hand-eye (flange poses)", "hand-eye");
    Table t({"item", "value"});
    t.Row({"start from the images", Text(At(hand_eye, {"start", "message"}))});
    t.Row({"image motions against the flange", Text(At(hand_eye, {"image_motions", "message"}))});
    t.Row({"pose-noise bundle", Text(At(hand_eye, {"pose_noise", "message"}))});
    t.Row({name + " translation (mm)", Mm(At(hand_eye, {key, "xyz_m"}))});
    t.Row({name + " rotation vector (deg)", Text(At(hand_eye, {key, "rotvec_rad"}), 5, kDeg)});
    t.Row({"sigma translation (mm)", Mm(At(hand_eye, {key, "stddev", "xyz_m"}))});
    page->Add(t);
  }
  const json& session = At(r, {"session"});
  if (!session.is_null()) {
    page->Heading(2, "Session", "session");
    Table t({"item", "value"});
    for (const char* key : {"path", "session_id", "poses_planned", "samples_accepted", "resumes", "finished",
                            "skips_by_reason", "faults_by_kind", "halts_by_reason", "warnings"}) {
      t.Row({key, Text(At(session, {key}))});
    }
    page->Add(t);
  }
}

}  // namespace

std::string CalibrationReportHtml(const json& r, const std::string& plotly_js) {
  Page page("selfcal calibration report: " + Text(At(r, {"input", "path"})));
  page.Heading(1, "selfcal calibration report");
  page.Paragraph("Input: " + Text(At(r, {"input", "kind"})) + " " + Text(At(r, {"input", "path"})) + " (SHA-256 " +
                     Text(At(r, {"input", "sha256"})) + "); selfcal " + Text(At(r, {"software_version"})) +
                     "; report format " + Text(At(r, {"format"})) + " version " + Text(At(r, {"version"})),
                 "meta");
  VerdictSection(r, &page);
  page.Heading(2, "Cameras and dots in 3-D", "scene");
  if (At(r, {"methods", "bundle"}).is_null()) {
    page.Paragraph("The bundle adjustment did not run (method " + Text(At(r, {"method"})) +
                       "): no camera poses or dots to show.",
                   "note");
  } else {
    html::SceneFigure(At(r, {"methods", "bundle", "plot_data"}), At(r, {"verification"}), &page);
  }
  ResidualSection(r, &page);
  ParameterSection(r, &page);
  IdentifiabilitySection(r, &page);
  HeldOutSection(r, &page);
  PaperSection(r, &page);
  ContextSection(r, &page);
  return page.Render(plotly_js);
}

Result<std::string> ReportHtml(const json& document, const std::string& plotly_js) {
  const json& format = At(document, {"format"});
  const json& version = At(document, {"version"});
  const std::string format_text = format.is_string() ? "\"" + format.get<std::string>() + "\"" : Text(format);
  if (format == kCalibrationReportFormat) {
    if (version != kCalibrationReportVersion) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "key `version`: " + Text(version) + " (this selfcal reads version " +
                               std::to_string(kCalibrationReportVersion) +
                               " of selfcal-calibration-report; calibrate again to get one)");
    }
    return CalibrationReportHtml(document, plotly_js);
  }
  if (format == kStudyFormat) {
    if (version != 1) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "key `version`: " + Text(version) + " (this selfcal reads version 1 of selfcal-study)");
    }
    return StudyReportHtml(document, plotly_js);
  }
  return Status::Error(ErrorCode::kInvalidInput,
                       "key `format`: " + format_text + " is neither \"" + std::string(kCalibrationReportFormat) +
                           "\" (calibrate's report.json) nor \"" + kStudyFormat + "\" (study's JSON output)");
}

}  // namespace selfcal::report
