#include "app/identify_options.h"

#include "session/setup_file.h"

namespace selfcal::app {

void AddIdentifyOptions(CLI::App* cmd, IdentifySettings* s, const std::string& default_help) {
  const char* group = "Dot identity (docs/real-hardware-quickstart.md)";
  cmd->add_option("--identify", s->method,
                  "Who names the first frame's dots: order, grid, apriltag, reference (" + default_help + ")")
      ->check(CLI::IsMember({"order", "grid", "apriltag", "reference"}))
      ->group(group);
  cmd->add_option("--grid-rows", s->grid_rows, "grid: rows of the dot grid")->check(CLI::Range(2, 1000))->group(group);
  cmd->add_option("--grid-cols", s->grid_cols, "grid: columns of the dot grid")
      ->check(CLI::Range(2, 1000))
      ->group(group);
  cmd->add_option("--grid-origin", s->grid_origin, "grid: origin marker (larger-dot, none)")
      ->check(CLI::IsMember({"larger-dot", "none"}))
      ->group(group);
  cmd->add_option("--tag-side-mm", s->tag_side_mm, "apriltag: outer side of the tags' black border, mm")
      ->check(CLI::PositiveNumber)
      ->group(group);
  cmd->add_option("--tag-dots-mm", s->tag_dots_mm,
                  "apriltag: x1,y1,x2,y2,... of the dots around every tag, mm, tag frame")
      ->delimiter(',')
      ->group(group);
  cmd->add_option("--tag-tolerance-px", s->tag_tolerance_px, "apriltag: a dot this close to its prediction is named")
      ->check(CLI::PositiveNumber)
      ->group(group);
  cmd->add_option("--reference-gate-px", s->reference_gate_px, "reference: gate around each reference dot, px")
      ->check(CLI::PositiveNumber)
      ->group(group);
}

Result<acquisition::IdentifierOptions> ToIdentifierOptions(const IdentifySettings& s, const std::string& fallback) {
  Result<acquisition::IdentifierKind> kind = acquisition::ParseIdentifierKind(s.method.empty() ? fallback : s.method);
  if (!kind.ok()) return kind.status();
  acquisition::IdentifierOptions o;
  o.kind = *kind;
  o.grid.rows = s.grid_rows;
  o.grid.cols = s.grid_cols;
  o.grid.origin_marker = s.grid_origin == "none" ? tracking::OriginMarker::kNone : tracking::OriginMarker::kLargerDot;
  o.tag_side_m = s.tag_side_mm * 1e-3;
  if (s.tag_dots_mm.size() % 2 != 0) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--tag-dots-mm: x,y pairs expected, got " + std::to_string(s.tag_dots_mm.size()) + " numbers");
  }
  for (size_t k = 0; k + 1 < s.tag_dots_mm.size(); k += 2) {
    o.tag_dots_m.emplace_back(s.tag_dots_mm[k] * 1e-3, s.tag_dots_mm[k + 1] * 1e-3);
  }
  o.tag_tolerance_px = s.tag_tolerance_px;
  o.reference_gate_px = s.reference_gate_px;
  if (Status v = o.Validate(); !v.ok()) return v;
  return o;
}

Result<std::unique_ptr<acquisition::DotIdentifier>> MakeIdentifier(const IdentifySettings& settings,
                                                                   const std::string& fallback,
                                                                   const std::string& setup_text,
                                                                   const std::string& setup_name) {
  Result<acquisition::IdentifierOptions> options = ToIdentifierOptions(settings, fallback);
  if (!options.ok()) return options.status();
  session::SetupNaming naming;
  if (options->kind == acquisition::IdentifierKind::kReference) {
    ObservationSet probe;
    if (Status s = session::ParseSetupFile(setup_text, setup_name, &probe, &naming); !s.ok()) return s;
  }
  return acquisition::MakeDotIdentifier(*options, naming.reference_dots);
}

}  // namespace selfcal::app
