#include "io/targets_file.h"

#include <sstream>

#include "io/atomic_file.h"
#include "io/transform_yaml.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {
namespace {

const Range kJointRange = Range::Closed(DegToRad(-720), DegToRad(720));

void ReadTarget(const yaml::YamlNode& node, const std::string& name, int num_joints, Problems* problems,
                std::vector<PoseTarget>* out) {
  MapReader map(node, name, problems);
  if (!map.ok()) return;
  PoseTarget target;
  bool ok = ReadTransform(&map, "pose", /*required=*/true, &target.base_from_target);
  if (map.Optional("seed_deg") || map.Optional("seed_rad")) {
    std::vector<double> seed;
    if (map.QuantityList("seed", Unit::kAngle, num_joints, kJointRange, &seed)) {
      target.seed = Eigen::Map<const Eigen::VectorXd>(seed.data(), static_cast<Eigen::Index>(seed.size()));
    } else {
      ok = false;
    }
  }
  map.Finish();
  if (ok) out->push_back(target);
}

}  // namespace

Result<TargetsFile> LoadTargetsFile(const std::string& path, int num_joints) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(path);
  MapReader root(doc->root, "", &problems);
  if (!CheckFormatAndVersion(&root, kTargetsFormat, kTargetsVersion)) {
    root.Abandon();
    return problems.ToStatus("targets");
  }
  TargetsFile file;
  root.OptionalName("robot", &file.robot);
  file.robot_line = root.KeyLine("robot");
  std::string frame;
  if (root.String("frame", &frame)) {
    if (frame == "camera" || frame == "flange") {
      file.camera_frame = frame == "camera";
    } else {
      problems.Add("`frame` = `" + frame + "` at " + problems.At(root.KeyLine("frame")) + " must be camera or flange");
    }
  }
  if (const yaml::YamlNode* list = root.Required("targets")) {
    if (!list->IsSequence() || list->items.empty()) {
      problems.Add("`targets` at " + problems.At(list->line) + " must be a non-empty sequence of targets");
    } else {
      for (size_t i = 0; i < list->items.size(); ++i) {
        ReadTarget(list->items[i], "targets[" + std::to_string(i) + "]", num_joints, &problems, &file.targets);
      }
    }
  }
  root.Finish();
  if (!problems.empty()) return problems.ToStatus("targets");
  return file;
}

Status SaveTargetsFile(const TargetsFile& file, const std::string& path) {
  std::ostringstream out;
  out << "# selfcal compensate's targets (docs/compensation.md), exact SI values.\n"
      << "format: " << kTargetsFormat << "\nversion: " << kTargetsVersion << "\n";
  if (!file.robot.empty()) out << "robot: " << YamlQuoted(file.robot) << "\n";
  out << "frame: " << (file.camera_frame ? "camera" : "flange") << "\ntargets:\n";
  for (const PoseTarget& t : file.targets) {
    out << "  - {pose: " << TransformYaml(t.base_from_target, TransformStyle::kExact);
    if (t.seed) out << ", seed_rad: " << YamlNumberList(*t.seed);
    out << "}\n";
  }
  return WriteFileAtomically(path, out.str());
}

}  // namespace selfcal::io
