// selfcal identify-tracker --data DIR [--holdout-every N] [--report FILE]: kinematic identification from
// laser-tracker nest poses (three SMRs on the flange) of the Fanuc data set's format (io/fanuc_tracker_csv.h),
// through the same relative-pose identification as the camera pipeline (external/tracker_identification.h).
// Prints the SMR-distance spread, the axis fits, the rank analysis and the held-out errors before (axis-fit
// nominal model) and after identification; writes a JSON report.
#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "external/tracker_identification.h"
#include "io/fanuc_tracker_csv.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "urdf/urdf_writer.h"

namespace selfcal::app {

namespace {
struct TrackerArgs {
  std::string data_dir;
  std::string file = "N1N2N3Jval.csv";
  int holdout_every = 3;
  double j3_coupling = 1.0;
  std::string report = "tracker_report.json";
  std::string out;  // the model's directory; empty: the report's
};

// --out, or the report's directory.
std::filesystem::path ModelDirectory(const TrackerArgs& args) {
  return !args.out.empty() ? std::filesystem::path(args.out) : std::filesystem::path(args.report).parent_path();
}

// The identified arm as calibrate writes it (calibrated_model.yaml, docs/calibrated-model-format.md) and,
// when the model's joints are the controller's (no J3 coupling), as calibrated.urdf. The model's base is the
// tracker frame and its "camera" the SMR nest (flange_from_cam = flange_from_nest).
Status WriteTrackerModel(const TrackerArgs& args, const std::string& data_path,
                         const external::TrackerIdentificationReport& r) {
  const std::filesystem::path dir = ModelDirectory(args);
  if (!args.out.empty()) {
    if (Status s = EnsureDirectory(args.out); !s.ok()) return s;
  }
  io::CalibratedModel model;
  model.model = ApplyParameters(r.nominal, r.rho_identified);
  model.parameters = r.rho_identified;
  model.source = "selfcal identify-tracker " + data_path + " (base: the tracker frame; flange_from_cam: the SMR nest)";
  std::ostringstream coupling;
  coupling << "q3 = J3 + " << args.j3_coupling << " * J2 (model joint 3 from the controller's J2 and J3)";
  model.provenance = {{"software_version", SELFCAL_VERSION},
                      {"input_sha256", FileSha256(data_path)},
                      {"method", "laser-tracker relative-pose identification (modules/external)"},
                      {"joint_coupling", coupling.str()}};
  const std::string model_path = (dir / "calibrated_model.yaml").string();
  if (Status s = io::SaveCalibratedModel(model, model_path); !s.ok()) return s;
  std::cout << "identified model: " << model_path << " (its joints are the model's: " << coupling.str() << ")\n";
  AddOutputFile("calibrated_model", model_path);
  if (args.j3_coupling != 0) {
    std::cout << "calibrated URDF: not written: the model's joint 3 is J3 + " << args.j3_coupling
              << " * J2, a coupling a URDF's independent joints cannot hold (--j3-coupling 0 for an uncoupled arm)\n";
    return Status::Ok();
  }
  urdf::UrdfNames names;
  names.base_link = "tracker";
  names.camera_link = "smr_nest";
  const std::string urdf_path = (dir / "calibrated.urdf").string();
  if (Status s = urdf::WriteUrdf(model.model, names, urdf_path); !s.ok()) return s;
  std::cout << "calibrated URDF: " << urdf_path << "\n";
  AddOutputFile("calibrated_urdf", urdf_path);
  return Status::Ok();
}

nlohmann::json ErrorsJson(const external::ErrorStats& e) {
  return {{"rows", e.count}, {"mean_mm", e.mean_m * 1e3}, {"rms_mm", e.rms_m * 1e3}, {"max_mm", e.max_m * 1e3},
          {"rms_rotation_deg", RadToDeg(e.rms_rotation_rad)}};
}

void PrintErrors(const char* title, const external::ErrorStats& e) {
  std::cout << "  " << title << " (" << e.count << " rows): mean " << e.mean_m * 1e3 << " mm, RMS " << e.rms_m * 1e3
            << " mm, max " << e.max_m * 1e3 << " mm, rotation RMS " << RadToDeg(e.rms_rotation_rad) << " deg\n";
}
// The command's options; the model's directory and the tracker file for the output-path check.
void AddTrackerOptions(CLI::App* cmd, const std::shared_ptr<TrackerArgs>& args) {
  cmd->add_option("--data", args->data_dir, "Folder holding the tracker file")->required();
  cmd->add_option("--file", args->file, "Tracker file inside --data");
  cmd->add_option("--holdout-every", args->holdout_every, "Hold out rows i % N == 1 (0: none)")->check(CLI::Range(0, 1000));
  cmd->add_option("--j3-coupling", args->j3_coupling, "Model q3 = J3 + c * J2 (Fanuc: 1)");
  AddOutputOption(cmd, "--report", &args->report, OutputKind::kFile, "JSON report to write");
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kDirectory,
                  "Directory of the identified model (calibrated_model.yaml, and calibrated.urdf without J3 coupling); "
                  "default: the report's directory",
                  {"calibrated_model.yaml", "calibrated.urdf"});
  SetOutputPathWhenEmpty(cmd, "--out", [args]() {
    const std::string dir = ModelDirectory(*args).string();
    return dir.empty() ? std::string(".") : dir;  // a report in the working directory
  });
  AddInputPaths(cmd, [args]() {
    return std::vector<std::string>{(std::filesystem::path(args->data_dir) / args->file).string()};
  });
}

}  // namespace

Command AddTrackerCommand(CLI::App& app) {
  auto args = std::make_shared<TrackerArgs>();
  CLI::App* cmd = app.add_subcommand("identify-tracker", "Kinematic identification from laser-tracker nest poses");
  AddTrackerOptions(cmd, args);
  return [args]() {
    const std::string path = (std::filesystem::path(args->data_dir) / args->file).string();
    const Result<std::vector<io::FanucTrackerRow>> rows = io::LoadFanucTrackerCsv(path);
    if (!rows.ok()) return Fail(rows.status());
    std::vector<external::SmrTriple> points;
    std::vector<Eigen::VectorXd> joints;
    for (const auto& row : *rows) {
      points.push_back(row.smr_in_tracker_m);
      joints.push_back(row.joints_rad);
    }
    external::TrackerIdentificationOptions options;
    options.holdout_every = args->holdout_every;
    options.j3_coupling = args->j3_coupling;
    const external::TrackerIdentificationReport r = external::RunTrackerIdentification(points, joints, options);

    std::cout << path << ": " << rows->size() << " rows\n";
    const auto& d = r.distances;
    std::cout << "SMR distances (mm, mean +- std, range): ";
    for (int k = 0; k < 3; ++k) {
      std::cout << d.mean_m[k] * 1e3 << " +- " << d.stddev_m[k] * 1e3 << " (" << d.range_m[k] * 1e3 << ")"
                << (k < 2 ? ", " : "\n");
    }
    std::cout << "repeated reference pose: " << r.repeat_rows << " rows, max nest distance " << r.repeat_max_m * 1e3
              << " mm\n";
    nlohmann::json axes = nlohmann::json::array();
    for (const auto& a : r.axes) {
      std::cout << "axis " << a.joint << " (" << a.rows.size() << " rows): radial RMS " << a.rms_radial_m * 1e3
                << " mm, out-of-plane RMS " << a.rms_out_of_plane_m * 1e3 << " mm, centres off axis "
                << a.max_centre_off_axis_m * 1e3 << " mm, rotation/joint angle " << a.angle_ratio << "\n";
      axes.push_back({{"joint", a.joint}, {"rows", a.rows.size()},
                      {"direction", {a.direction.x(), a.direction.y(), a.direction.z()}},
                      {"point_mm", {a.point.x() * 1e3, a.point.y() * 1e3, a.point.z() * 1e3}},
                      {"rms_radial_mm", a.rms_radial_m * 1e3}, {"rms_out_of_plane_mm", a.rms_out_of_plane_m * 1e3},
                      {"max_centre_off_axis_mm", a.max_centre_off_axis_m * 1e3}, {"angle_ratio", a.angle_ratio}});
    }
    nlohmann::json doc = {{"format", "selfcal-tracker-report"}, {"version", 1}, {"data", path},
                          {"data_hash", FileSha256(path)}, {"outcome", external::OutcomeName(r.outcome)},
                          {"message", r.message}, {"holdout_every", args->holdout_every},
                          {"j3_coupling", args->j3_coupling},
                          {"smr_distances_mm", {{"mean", {d.mean_m[0] * 1e3, d.mean_m[1] * 1e3, d.mean_m[2] * 1e3}},
                                                {"stddev", {d.stddev_m[0] * 1e3, d.stddev_m[1] * 1e3, d.stddev_m[2] * 1e3}},
                                                {"range", {d.range_m[0] * 1e3, d.range_m[1] * 1e3, d.range_m[2] * 1e3}}}},
                          {"repeat_rows", r.repeat_rows}, {"repeat_max_mm", r.repeat_max_m * 1e3}, {"axes", axes}};
    if (!r.nominal.links.empty()) {
      nlohmann::json links = nlohmann::json::array();
      std::cout << "nominal model from the axis lines (modified DH + beta; tracker = base frame):\n";
      for (int j = 0; j < r.nominal.num_joints(); ++j) {
        const LinkParameters& l = r.nominal.links[j];
        std::cout << "  j" << j + 1 << ": alpha " << RadToDeg(l.alpha) << " deg, a " << l.a * 1e3 << " mm, beta "
                  << RadToDeg(l.beta) << " deg, theta " << RadToDeg(l.theta) << " deg, d " << l.d * 1e3 << " mm\n";
        links.push_back({{"alpha_deg", RadToDeg(l.alpha)}, {"a_mm", l.a * 1e3}, {"beta_deg", RadToDeg(l.beta)},
                         {"theta_deg", RadToDeg(l.theta)}, {"d_mm", l.d * 1e3}});
      }
      doc["nominal_links"] = links;
      doc["reference_row"] = r.reference_row;
      doc["identification_rows"] = r.identification_rows;
      doc["holdout_rows"] = r.holdout_rows;
      std::cout << "identifiable: " << r.identifiability.rank << " of " << r.identifiability.num_parameters
                << " parameters; fixed:";
      for (const auto& name : r.identifiability.fixed_names) std::cout << " " << name;
      std::cout << "\n";
      doc["free_parameters"] = r.identifiability.free_names;
      doc["fixed_parameters"] = r.identifiability.fixed_names;
      doc["identification"] = {{"outcome", identification::OutcomeName(r.identification.outcome)},
                               {"iterations", r.identification.iterations},
                               {"termination", r.identification.termination}};
      if (r.rho_identified.size() == r.rho_nominal.size()) {
        const KinematicParameters params(r.nominal.num_joints());
        nlohmann::json corrections = nlohmann::json::object();
        for (int i : r.identifiability.free_indices) {
          const double delta = r.rho_identified[i] - r.rho_nominal[i];
          corrections[params.name(i)] = params.kind(i) == ParameterKind::kLength ? delta * 1e3 : RadToDeg(delta);
        }
        doc["corrections_mm_or_deg"] = corrections;
      }
    }
    std::cout << "nest_ref_from_nest_i position errors, reference row " << r.reference_row + 1 << " (1-based):\n";
    PrintErrors("held-out, before (axis-fit model)", r.holdout_before);
    PrintErrors("held-out, after identification   ", r.holdout_after);
    PrintErrors("in-sample, before                ", r.insample_before);
    PrintErrors("in-sample, after                 ", r.insample_after);
    const double ratio = r.insample_after.rms_m > 0 ? r.holdout_after.rms_m / r.insample_after.rms_m : 0.0;
    std::cout << "held-out / in-sample RMS after identification: " << ratio << "\n";
    doc["holdout_before"] = ErrorsJson(r.holdout_before);
    doc["holdout_after"] = ErrorsJson(r.holdout_after);
    doc["insample_before"] = ErrorsJson(r.insample_before);
    doc["insample_after"] = ErrorsJson(r.insample_after);
    doc["holdout_over_insample_rms"] = ratio;
    if (const Status s = io::WriteJsonFile(doc, args->report); !s.ok()) return Fail(s);
    std::cout << "report: " << args->report << "\n";
    if (r.outcome == external::Outcome::kSuccess) {
      if (const Status s = WriteTrackerModel(*args, path, r); !s.ok()) return Fail(s);
    }
    if (r.outcome != external::Outcome::kSuccess) {
      std::cerr << "selfcal: identify-tracker: " << external::OutcomeName(r.outcome) << ": " << path;
      if (r.problem_row >= 0) std::cerr << ":" << (*rows)[static_cast<size_t>(r.problem_row)].line;
      std::cerr << ": " << r.message << "\n";
      const ExitCode code = r.outcome == external::Outcome::kInvalidInput  ? ExitCode::kUsage
                            : r.outcome == external::Outcome::kDegenerate ? ExitCode::kDegenerateData
                                                                           : ExitCode::kSolverFailure;
      return static_cast<int>(code);
    }
    return 0;
  };
}

}  // namespace selfcal::app
