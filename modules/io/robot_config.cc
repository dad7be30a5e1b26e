#include "io/robot_config.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <tuple>

#include "io/atomic_file.h"
#include "io/observations_file.h"
#include "io/robot_origin.h"
#include "io/urdf_robot_config.h"
#include "yaml/yaml_reader.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

namespace {

constexpr int kMaxJoints = 32;
constexpr double kMaxLinkLengthM = 10.0;  // as RobotModel::Validate
const Range kLinkLength = Range::Closed(-kMaxLinkLengthM, kMaxLinkLengthM);
const Range kLinkAngle = Range::Closed(DegToRad(-360), DegToRad(360));
const Range kJointLimit = Range::Closed(DegToRad(-720), DegToRad(720));

enum class Convention { kStandard, kModified, kModifiedHayati, kInvalid };

Convention ReadConvention(MapReader* map) {
  std::string text;
  if (!map->String("dh_convention", &text)) return Convention::kInvalid;
  if (text == "standard") return Convention::kStandard;
  if (text == "modified") return Convention::kModified;
  if (text == "modified_hayati") return Convention::kModifiedHayati;
  const yaml::YamlNode* node = map->Optional("dh_convention");
  map->problems()->Add("`" + map->Path("dh_convention") + "` = `" + text + "` at " +
                       map->problems()->At(node->line) + " must be one of standard, modified, modified_hayati");
  return Convention::kInvalid;
}

struct JointRow {
  LinkParameters link;  // alpha, a, beta, theta, d as written (convention-specific meaning)
  JointLimits limits;
  std::string joint_name, link_name;  // optional, for the exports
};

bool ReadJoint(const yaml::YamlNode& node, const std::string& name, Convention convention, Problems* problems,
               JointRow* row) {
  MapReader map(node, name, problems);
  if (!map.ok()) return false;
  LinkParameters& l = row->link;
  bool ok = map.Quantity("a", Unit::kLength, kLinkLength, &l.a);
  ok &= map.Quantity("alpha", Unit::kAngle, kLinkAngle, &l.alpha);
  ok &= map.Quantity("d", Unit::kLength, kLinkLength, &l.d);
  ok &= map.Quantity("theta_offset", Unit::kAngle, kLinkAngle, &l.theta, /*required=*/false);
  if (convention == Convention::kStandard || convention == Convention::kModified) {
    const std::string reason = "a Hayati beta needs dh_convention: modified_hayati";
    map.Disallow("beta_deg", reason);
    map.Disallow("beta_rad", reason);
  } else {
    ok &= map.Quantity("beta", Unit::kAngle, kLinkAngle, &l.beta, /*required=*/false);
  }
  // For the exports only (io/robot_origin.h reads them): the joint's and its link's names in calibrated.urdf,
  // the joint's rated speed as its <limit velocity>.
  ok &= map.OptionalName("name", &row->joint_name);
  ok &= map.OptionalName("link", &row->link_name);
  double velocity_deg_s = 0;
  ok &= map.OptionalDouble("max_velocity_deg_s", Range::Positive(1e5), &velocity_deg_s);
  const bool min_ok = map.Quantity("min", Unit::kAngle, kJointLimit, &row->limits.min_rad);
  const bool max_ok = map.Quantity("max", Unit::kAngle, kJointLimit, &row->limits.max_rad);
  if (min_ok && max_ok && !(row->limits.min_rad < row->limits.max_rad)) {
    problems->Add("joint limits of `" + name + "` at " + problems->At(node.line) + ": min " +
                  std::to_string(RadToDeg(row->limits.min_rad)) + " deg is not below max " +
                  std::to_string(RadToDeg(row->limits.max_rad)) + " deg");
    ok = false;
  }
  map.Finish();
  return ok && min_ok && max_ok;
}

// The joints' `name`s and `link`s become calibrated.urdf's: each used once, and no link named like the
// URDF's other links (urdf/urdf_writer.h).
bool CheckExportNames(const std::vector<JointRow>& rows, const std::vector<int>& row_lines, Problems* problems) {
  std::map<std::string, size_t> joints, links = {{"base_link", 0}, {"link0", 0}, {"tool0", 0}, {"camera_optical_frame", 0}};
  bool ok = true;
  for (size_t i = 0; i < rows.size() && i < row_lines.size(); ++i) {
    for (auto [name, seen, what] : {std::tuple{rows[i].joint_name, &joints, "joint name"},
                                    std::tuple{rows[i].link_name, &links, "link name"}}) {
      if (name.empty()) continue;
      if (!seen->emplace(name, i + 1).second) {
        const size_t other = seen->at(name);
        problems->Add(std::string(what) + " `" + name + "` of joint " + std::to_string(i + 1) + " at " +
                      problems->At(row_lines[i]) + " is already " +
                      (other == 0 ? "a link of the calibrated URDF" : "that of joint " + std::to_string(other)));
        ok = false;
      }
    }
  }
  return ok;
}

void ReadParameters(MapReader* root, int num_joints, Eigen::VectorXd* out) {
  const yaml::YamlNode* node = root->Optional("parameters");
  if (!node || num_joints <= 0) return;
  MapReader map(*node, root->Path("parameters"), root->problems());
  if (!map.ok()) return;
  const KinematicParameters names(num_joints);
  Eigen::VectorXd rho(names.size());
  bool ok = true;
  for (int i = 0; i < names.size(); ++i) {
    const bool length = names.kind(i) == ParameterKind::kLength;
    ok &= map.Quantity(names.name(i), length ? Unit::kLength : Unit::kAngle, length ? kLinkLength : kJointLimit, &rho[i]);
  }
  map.Finish();
  if (ok) *out = rho;
}

void ReadProvenance(MapReader* root, std::vector<std::pair<std::string, std::string>>* out) {
  const yaml::YamlNode* node = root->Optional("provenance");
  if (!node) return;
  MapReader map(*node, root->Path("provenance"), root->problems());
  if (!map.ok()) return;
  for (size_t i = 0; i < node->keys.size(); ++i) {
    std::string value;
    if (ReadString(node->items[i], map.Path(node->keys[i]), root->problems(), &value)) {
      out->emplace_back(node->keys[i], value);
    }
    map.Optional(node->keys[i]);  // free-form: every key is allowed
  }
}

// `home_deg` / `home_rad`: one angle per joint row, each inside its joint's limits.
bool ReadHome(MapReader* map, const std::vector<JointRow>& rows, std::vector<double>* home) {
  std::string key;
  std::vector<int> lines;
  if (!map->QuantityList("home", Unit::kAngle, static_cast<int>(rows.size()), kJointLimit, home, /*required=*/false,
                         &key, &lines)) {
    return false;
  }
  bool ok = true;
  for (size_t j = 0; j < home->size() && j < rows.size() && j < lines.size(); ++j) {
    const JointLimits& l = rows[j].limits;
    if ((*home)[j] < l.min_rad || (*home)[j] > l.max_rad) {
      map->problems()->Add("`" + map->Path(key) + "[" + std::to_string(j) + "]` at " + map->problems()->At(lines[j]) +
                           ": joint " + std::to_string(j + 1) + " = " + std::to_string(RadToDeg((*home)[j])) +
                           " deg is outside its limits [" + std::to_string(RadToDeg(l.min_rad)) + ", " +
                           std::to_string(RadToDeg(l.max_rad)) + "] deg");
      ok = false;
    }
  }
  return ok;
}

// A calibrated model's `configuration` (eye_in_hand by default) and, for eye_to_hand, its required
// `base_from_cam`, the calibrated fixed camera (`flange_from_cam` is then the robot config's, unused).
bool ReadCalibratedMount(MapReader* map, CameraMount* mount, Rigid3* base_from_cam) {
  std::string name = CameraMountName(CameraMount::kEyeInHand);
  if (map->Optional("configuration") != nullptr && !map->OptionalString("configuration", &name)) return false;
  if (!ParseCameraMount(name, mount)) {
    map->problems()->Add("`" + map->Path("configuration") + "` = `" + name + "` at " +
                         map->problems()->At(map->KeyLine("configuration")) + " must be eye_in_hand or eye_to_hand");
    return false;
  }
  if (*mount == CameraMount::kEyeToHand) return ReadTransform(map, "base_from_cam", /*required=*/true, base_from_cam);
  map->Disallow("base_from_cam", "only with `configuration: eye_to_hand`");
  return true;
}

// The keys only a calibrated model has: its configuration and fixed camera (into *mounted's mount and
// base_from_cam), fx_px, camera, intrinsics_stddev, parameters, provenance.
bool ReadCalibratedKeys(MapReader* map, int num_joints, CalibratedModel* out, RobotModel* mounted) {
  bool ok = ReadCalibratedMount(map, &mounted->mount, &mounted->base_from_cam);
  ok &= map->OptionalDouble("fx_px", Range::Positive(1e6), &out->fx_px);
  ok &= ReadOptionalCamera(map, map->problems(), &out->camera);
  ok &= ReadIntrinsicsStddev(map, &out->intrinsics_stddev);
  ReadParameters(map, num_joints, &out->parameters);
  ReadProvenance(map, &out->provenance);
  return ok;
}

CalibratedModel Parse(const yaml::YamlNode& node, const std::string& name, Problems* problems, std::string* format) {
  CalibratedModel out;
  const size_t problems_before = problems->size();
  MapReader map(node, name, problems);
  if (!map.ok()) return out;
  if (const yaml::YamlNode* f = map.Optional("format")) {
    if (!ReadString(*f, map.Path("format"), problems, format)) return out;
    if (*format != kRobotFormat && *format != kCalibratedModelFormat) {
      problems->Add("`" + map.Path("format") + "` = `" + *format + "` at " + problems->At(f->line) + ": expected `" +
                    kRobotFormat + "` or `" + kCalibratedModelFormat + "`; is this a robot file?");
      map.Abandon();
      return out;
    }
    if (!CheckVersion(&map, *format, kCalibratedModelVersion)) {
      map.Abandon();
      return out;
    }
  } else if (map.Optional("version")) {
    CheckVersion(&map, kRobotFormat, kCalibratedModelVersion);
  }
  const bool calibrated = *format == kCalibratedModelFormat;
  if (!calibrated && NamesUrdf(node)) {
    ParseUrdfRobotConfig(&map, problems, &out);
    return out;
  }

  RobotModel& model = out.model;
  bool ok = map.String("name", &model.name);
  if (ok && model.name.empty()) {
    problems->Add("`" + map.Path("name") + "` at " + problems->At(map.KeyLine("name")) + " is empty");
    ok = false;
  }
  map.OptionalString("source", &out.source);
  const Convention convention = ReadConvention(&map);
  ok &= convention != Convention::kInvalid;

  std::vector<JointRow> rows;
  std::vector<int> row_lines;  // of each joint row, for the model's own checks below
  if (const yaml::YamlNode* joints = map.Required("joints")) {
    const std::string path = map.Path("joints");
    if (!joints->IsSequence() || joints->items.empty() || static_cast<int>(joints->items.size()) > kMaxJoints) {
      problems->Add("`" + path + "` at " + problems->At(joints->line) + " must be a sequence of 1 to " +
                    std::to_string(kMaxJoints) + " joint rows (found " +
                    (joints->IsSequence() ? std::to_string(joints->items.size()) + " rows" : joints->KindName()) + ")");
      ok = false;
    } else {
      rows.resize(joints->items.size());
      for (size_t i = 0; i < rows.size(); ++i) {
        row_lines.push_back(joints->items[i].line);
        ok &= ReadJoint(joints->items[i], path + "[" + std::to_string(i) + "]", convention, problems, &rows[i]);
      }
    }
  } else {
    ok = false;
  }

  ok &= CheckExportNames(rows, row_lines, problems);
  RobotOrigin origin;
  if (convention == Convention::kModifiedHayati) {
    ok &= ReadEnteredAs(&map, &origin);  // io/robot_origin.h: read for the exports, no part of the model
  } else {
    map.Disallow("entered_as", "only with dh_convention: modified_hayati (the form selfcal writes)");
  }
  if (origin.FromUrdf() && origin.joint_names.size() != rows.size()) {
    problems->Add("`" + map.Path("entered_as") + "` names " + std::to_string(origin.joint_names.size()) +
                  " joints, the table has " + std::to_string(rows.size()));
    ok = false;
  }
  Rigid3 base_from_link0, flange_from_cam, link_n_from_flange;
  ok &= ReadTransform(&map, "base_from_link0", /*required=*/false, &base_from_link0);
  ok &= ReadTransform(&map, "flange_from_cam", /*required=*/true, &flange_from_cam);
  if (convention == Convention::kStandard) {
    map.Disallow("link_n_from_flange", "with dh_convention: standard the last row's a and alpha define it");
  } else {
    ok &= ReadTransform(&map, "link_n_from_flange", /*required=*/false, &link_n_from_flange);
  }
  RobotModel mounted;  // a calibrated model's configuration and fixed camera, set once the model is built
  if (calibrated) {
    ok &= ReadCalibratedKeys(&map, static_cast<int>(rows.size()), &out, &mounted);
  } else {
    for (const char* key : {"fx_px", "camera", "intrinsics_stddev", "parameters", "provenance", "configuration", "base_from_cam"}) {
      map.Disallow(key, std::string("only in a `format: ") + kCalibratedModelFormat + "` file");
    }
  }
  if (ok) {
    ok &= ReadHome(&map, rows, &out.home_rad);
  } else {  // the rows are not known: the home is checked once they are
    map.Optional("home_deg");
    map.Optional("home_rad");
  }
  map.Finish();
  if (!ok || problems->size() != problems_before) return out;

  std::vector<DhRow> dh;
  std::vector<JointLimits> limits;
  for (const JointRow& row : rows) {
    dh.push_back(DhRow{row.link.a, row.link.alpha, row.link.d, row.link.theta});
    limits.push_back(row.limits);
  }
  const std::string robot_name = model.name;
  model = RobotModel::FromDh(robot_name, convention == Convention::kStandard ? DhConvention::kStandard : DhConvention::kModified,
                             dh, limits, base_from_link0, flange_from_cam);
  if (convention != Convention::kStandard) {
    for (size_t i = 0; i < rows.size(); ++i) model.links[i].beta = rows[i].link.beta;
    model.link_n_from_flange = link_n_from_flange;
  }
  model.mount = mounted.mount;
  model.base_from_cam = mounted.base_from_cam;
  // The model's own checks, each at the line of the joint row it names ("joint 3: ..."), else the robot's.
  std::istringstream invalid(model.Validate());
  for (std::string line; std::getline(invalid, line);) {
    int joint = 0;
    const bool of_a_joint = std::sscanf(line.c_str(), "joint %d:", &joint) == 1 && joint >= 1 &&
                            joint <= static_cast<int>(row_lines.size());
    problems->Add("robot `" + model.name + "` at " + problems->At(of_a_joint ? row_lines[joint - 1] : map.line()) + ": " +
                  line);
  }
  return out;
}

std::string Indent(int n) { return std::string(static_cast<size_t>(n), ' '); }

}  // namespace

CalibratedModel ParseRobotModel(const yaml::YamlNode& node, const std::string& name, Problems* problems) {
  std::string format;
  return Parse(node, name, problems, &format);
}

namespace {

Result<RobotModel> RobotModelOf(const Result<yaml::YamlDocument>& doc, const std::string& name) {
  if (!doc.ok()) return doc.status();
  Problems problems(name);
  std::string format;
  CalibratedModel parsed = Parse(doc->root, "", &problems, &format);
  if (!problems.empty()) return problems.ToStatus("robot model");
  return parsed.model;
}

}  // namespace

Result<RobotModel> LoadRobotModel(const std::string& path) { return RobotModelOf(yaml::LoadYamlFile(path), path); }

Result<RobotModel> ParseRobotModelText(const std::string& text, const std::string& name) {
  return RobotModelOf(yaml::ParseYamlText(text, name), name);
}

namespace {

// The whole file; `calibrated_only`: refused unless it is a calibrated model.
Result<CalibratedModel> LoadRobotFile(const std::string& path, bool calibrated_only) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(path);
  std::string format;
  CalibratedModel parsed = Parse(doc->root, "", &problems, &format);
  if (calibrated_only && problems.empty() && format != kCalibratedModelFormat) {
    problems.Add(path + " is a robot config, not a calibrated model (no `format: " + kCalibratedModelFormat + "`)");
  }
  if (!problems.empty()) return problems.ToStatus(calibrated_only ? "calibrated model" : "robot model");
  return parsed;
}

}  // namespace

Result<CalibratedModel> LoadRobotConfig(const std::string& path) { return LoadRobotFile(path, false); }

Result<CalibratedModel> LoadCalibratedModel(const std::string& path) { return LoadRobotFile(path, true); }

std::string RobotModelYaml(const RobotModel& model, TransformStyle style, int indent) {
  const bool exact = style == TransformStyle::kExact;
  const std::string pad = Indent(indent);
  // Exact: the stored bits, -0 included. For people: "+ 0.0" turns -0 into 0.
  const auto angle = [&](double rad) { return YamlNumber(exact ? rad : RadToDeg(rad) + 0.0); };
  const auto length = [&](double m) { return YamlNumber(exact ? m : m * 1000.0 + 0.0); };
  const char* a_unit = exact ? "_rad: " : "_deg: ";
  const char* l_unit = exact ? "_m: " : "_mm: ";
  std::ostringstream out;
  out << pad << "name: " << YamlQuoted(model.name) << "\n";
  out << pad << "dh_convention: modified_hayati\n";
  out << pad << "joints:  # link i: Rx(alpha) Tx(a) Ry(beta) Rz(q + theta_offset) Tz(d)\n";
  for (int i = 0; i < model.num_joints(); ++i) {
    const LinkParameters& l = model.links[i];
    const JointLimits limits = i < static_cast<int>(model.limits.size()) ? model.limits[i] : JointLimits{};
    out << pad << "  - {alpha" << a_unit << angle(l.alpha) << ", a" << l_unit << length(l.a) << ", beta" << a_unit
        << angle(l.beta) << ", theta_offset" << a_unit << angle(l.theta) << ", d" << l_unit << length(l.d) << ", min"
        << a_unit << angle(limits.min_rad) << ", max" << a_unit << angle(limits.max_rad) << "}\n";
  }
  out << pad << "base_from_link0: " << TransformYaml(model.base_from_link0, style) << "\n";
  out << pad << "link_n_from_flange: " << TransformYaml(model.link_n_from_flange, style) << "\n";
  out << pad << "flange_from_cam: " << TransformYaml(model.flange_from_cam, style) << "\n";
  return out.str();
}

Status SaveCalibratedModel(const CalibratedModel& calibrated, const std::string& path) {
  const RobotModel& model = calibrated.model;
  std::string problems = model.Validate();
  if (!std::isfinite(calibrated.fx_px) || calibrated.fx_px < 0) problems += "fx_px is not finite and >= 0\n";
  if (calibrated.parameters.size() != 0 && calibrated.parameters.size() != model.num_parameters()) {
    problems += "the parameter vector has " + std::to_string(calibrated.parameters.size()) + " entries, the model needs " +
                std::to_string(model.num_parameters()) + "\n";
  }
  if (!calibrated.parameters.allFinite()) problems += "the parameter vector is not finite\n";
  if (calibrated.camera) {
    if (const std::string invalid = calibrated.camera->Validate(); !invalid.empty()) problems += "camera: " + invalid;
  }
  for (const auto& [key, value] : calibrated.provenance) {
    if (key.empty()) problems += "empty provenance key\n";
  }
  if (!problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "refusing to write an invalid calibrated model to " + path + ":\n" + problems);
  }
  const bool eye_to_hand = model.mount == CameraMount::kEyeToHand;
  std::ostringstream out;
  out << "# selfcal calibrated robot model (docs/calibrated-model-format.md). Lengths in mm, angles in degrees.\n"
      << (eye_to_hand ? "# base_from_flange(q) = base_from_link0 * link_1(q_1) * ... * link_n(q_n) * link_n_from_flange; the camera\n"
                        "# is fixed at base_from_cam (eye-to-hand)\n"
                      : "# base_from_cam(q) = base_from_link0 * link_1(q_1) * ... * link_n(q_n) * link_n_from_flange * flange_from_cam\n")
      << "format: " << kCalibratedModelFormat << "\n"
      // 1.1 added the eye-to-hand configuration: an eye-in-hand model stays readable by every 1.x reader.
      << "version: " << (eye_to_hand ? "1.1" : std::to_string(kCalibratedModelVersion)) << "\n";
  if (!calibrated.source.empty()) out << "source: " << YamlQuoted(calibrated.source) << "\n";
  out << RobotModelYaml(model, TransformStyle::kMillimetreDegree, 0);
  if (eye_to_hand) {
    out << "configuration: " << CameraMountName(model.mount) << "  # the camera fixed, the points on the flange\n"
        << "base_from_cam: " << TransformYaml(model.base_from_cam, TransformStyle::kMillimetreDegree)
        << "  # the calibrated fixed camera (flange_from_cam above takes no part)\n";
  }
  if (calibrated.fx_px > 0) out << "fx_px: " << YamlNumber(calibrated.fx_px) << "\n";
  if (calibrated.camera) out << "camera: " << CameraYaml(*calibrated.camera) << "  # the calibrated intrinsics\n";
  if (const std::string sd = IntrinsicsStddevYaml(calibrated.intrinsics_stddev); !sd.empty()) {
    out << "intrinsics_stddev: " << sd << "  # of the estimated intrinsics\n";
  }
  if (calibrated.parameters.size() > 0) {
    out << "parameters:  # rho of kinematics/robot_model.h (base and camera corrections, link values)\n";
    const KinematicParameters names(model.num_joints());
    for (int i = 0; i < names.size(); ++i) {
      const double v = calibrated.parameters[i];
      const bool length = names.kind(i) == ParameterKind::kLength;
      out << "  " << names.name(i) << (length ? "_mm: " : "_deg: ") << YamlNumber((length ? v * 1000.0 : RadToDeg(v)) + 0.0)
          << "\n";
    }
  }
  if (!calibrated.provenance.empty()) {
    out << "provenance:\n";
    for (const auto& [key, value] : calibrated.provenance) out << "  " << YamlQuoted(key) << ": " << YamlQuoted(value) << "\n";
  }
  return WriteFileAtomically(path, out.str());
}

}  // namespace selfcal::io
