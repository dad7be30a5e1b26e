#include "io/pose_files.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <system_error>

#include <Eigen/Geometry>

#include "base/atomic_file.h"
#include "base/short_number.h"
#include "io/plausible_limits.h"
#include "io/transform_yaml.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

namespace {

const Range kTranslation = Range::Closed(-kMaxTranslationM, kMaxTranslationM);

// Form (a): x, y, z (m) and the unit quaternion qx, qy, qz, qw.
bool ReadRosPose(MapReader* root, Problems* problems, Rigid3* out) {
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1};
  const char* const kT[] = {"x", "y", "z"};
  const char* const kQ[] = {"qx", "qy", "qz", "qw"};
  bool ok = true;
  for (int i = 0; i < 3; ++i) ok &= root->Double(kT[i], kTranslation, &t[i]);
  for (int i = 0; i < 4; ++i) ok &= root->Double(kQ[i], Range::Closed(-1.001, 1.001), &q[i]);
  if (!ok) return false;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
    problems->Add("the quaternion (qx, qy, qz, qw) at " + problems->At(root->KeyLine("qx")) + " has norm " +
                  ShortNumber(norm) + ", not 1 (within " + ShortNumber(kQuaternionNormTolerance) + ")");
    return false;
  }
  const Eigen::Quaterniond quaternion(q[3] / norm, q[0] / norm, q[1] / norm, q[2] / norm);
  *out = Rigid3(quaternion.toRotationMatrix(), Eigen::Vector3d(t[0], t[1], t[2]));
  return true;
}

// One element of a vpPoseVector's `data`: `[v]` as ViSP writes it, or a plain number.
bool ReadPoseVectorElement(const yaml::YamlNode& item, const std::string& name, const Range& range,
                           Problems* problems, double* out) {
  if (item.IsSequence()) {
    std::vector<double> one;
    if (!ReadDoubleList(item, name, 1, range, problems, &one)) return false;
    *out = one[0];
    return true;
  }
  return ReadDouble(item, name, range, problems, out);
}

// Form (b): rows: 6, cols: 1, data: [[tx], [ty], [tz], [tux], [tuy], [tuz]] (m, theta-u rad).
bool ReadVispPose(MapReader* root, Problems* problems, Rigid3* out) {
  long long rows = 0, cols = 0;
  bool ok = root->Int("rows", 6, 6, &rows);
  ok &= root->Int("cols", 1, 1, &cols);
  const yaml::YamlNode* data = root->Required("data");
  if (data == nullptr) return false;
  if (!data->IsSequence() || data->items.size() != 6) {
    problems->Add("`data` at " + problems->At(data->line) +
                  " must be a list of 6 rows [tx], [ty], [tz] (m), [tux], [tuy], [tuz] (theta-u, rad), not a " +
                  (data->IsSequence() ? "list of " + std::to_string(data->items.size()) : std::string(data->KindName())));
    return false;
  }
  double v[6];
  for (int i = 0; i < 6; ++i) {
    const Range range = i < 3 ? kTranslation : Range::Closed(-2 * kPi, 2 * kPi);
    ok &= ReadPoseVectorElement(data->items[static_cast<size_t>(i)], "data[" + std::to_string(i) + "]", range,
                                problems, &v[i]);
  }
  if (!ok) return false;
  const Eigen::Vector3d theta_u(v[3], v[4], v[5]);
  if (theta_u.norm() > 2 * kPi) {
    problems->Add("the theta-u rotation `data[3..5]` at " + problems->At(data->line) + " has angle " +
                  ShortNumber(theta_u.norm()) + " rad, more than 2 pi");
    return false;
  }
  *out = Rigid3(ExpSO3<double>(theta_u), Eigen::Vector3d(v[0], v[1], v[2]));
  return true;
}

// One entry of a poses list: `image` and exactly one of `base_from_flange` and joints.
bool ReadListEntry(const yaml::YamlNode& node, const std::string& name, const RobotModel* robot, Problems* problems,
                   ImagePose* pose) {
  MapReader map(node, name, problems);
  if (!map.ok()) return false;
  std::string image;
  bool ok = map.String("image", &image);
  if (ok && image.empty()) {
    problems->Add("`" + map.Path("image") + "` at " + problems->At(map.KeyLine("image")) + " is empty");
    ok = false;
  }
  pose->key = ImageKey(image);
  pose->source = problems->At(node.line);
  std::string role = "identification";
  if (map.OptionalString("role", &role) && role != "identification") {
    if (role == "verification") {
      pose->verification = true;
    } else {
      problems->Add("`" + map.Path("role") + "` = `" + role + "` at " + problems->At(map.KeyLine("role")) +
                    " must be identification or verification");
      ok = false;
    }
  }
  const bool has_flange = map.Optional("base_from_flange") != nullptr;
  const bool has_joints = node.Find("joints_deg") != nullptr || node.Find("joints_rad") != nullptr;
  if (has_flange == has_joints) {
    problems->Add("pose `" + name + "` at " + problems->At(node.line) + " must give exactly one of `base_from_flange`"
                  " and `joints_deg` (or `joints_rad`)");
    map.Optional("joints_deg");
    map.Optional("joints_rad");
    map.Finish();
    return false;
  }
  if (has_flange) {
    Rigid3 flange;
    if (ReadTransform(&map, "base_from_flange", true, &flange, &pose->rotation_correction_rad)) {
      pose->base_from_flange = flange;
    } else {
      ok = false;
    }
  } else if (robot == nullptr) {
    problems->Add("`" + name + "` at " + problems->At(node.line) +
                  " gives joint angles: they need the robot's config (selfcal detect --robot)");
    map.Optional("joints_deg");
    map.Optional("joints_rad");
    ok = false;
  } else {
    // Values outside the robot's limits are kept: the controller's reading is what happened (calibrate
    // warns, observations/joint_limits.h); only the plausible range is checked, and radians under a degree key.
    std::vector<double> joints;
    if (map.JointAngles(robot->num_joints(), &joints)) {
      pose->joints_rad = Eigen::Map<const Eigen::VectorXd>(joints.data(), static_cast<Eigen::Index>(joints.size()));
    } else {
      ok = false;
    }
  }
  map.Finish();
  return ok;
}

bool IsDirectory(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

bool HasGlobCharacters(const std::string& spec) { return spec.find_first_of("*?[") != std::string::npos; }

bool IsJson(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".json";
}

// A recorded tool pose made the flange's: base_from_flange = base_from_tool * flange_from_tool^-1.
Status ToolToFlange(const PoseReadOptions& options, ImagePose* pose) {
  if (!options.flange_from_tool) return Status::Ok();
  if (!pose->base_from_flange) {
    return Status::Error(ErrorCode::kInvalidInput,
                         pose->source + ": gives joint angles; a tool frame (--flange-from-tool-mm-deg) applies to "
                                        "recorded tool poses only");
  }
  pose->base_from_flange = *pose->base_from_flange * options.flange_from_tool->Inverse();
  return Status::Ok();
}

}  // namespace

Result<ImagePose> LoadPoseFile(const std::string& path, const RobotModel* robot, const PoseReadOptions& options) {
  ImagePose pose;
  pose.key = ImageKey(path);
  pose.source = path;
  if (IsJson(path)) {
    if (options.json.empty()) {
      return Status::Error(ErrorCode::kInvalidInput,
                           path + ": a JSON pose file: name the key of its pose (--pose-joints-key, --pose-matrix-key, "
                                  "or --pose-position-key with --pose-quaternion-key)");
    }
    if (Status s = LoadJsonPoseFile(path, options.json, robot, &pose); !s.ok()) return s;
  } else {
    Result<Rigid3> transform = LoadPerImagePoseFile(path);
    if (!transform.ok()) return transform.status();
    pose.base_from_flange = *transform;
  }
  if (Status s = ToolToFlange(options, &pose); !s.ok()) return s;
  return pose;
}

Result<Rigid3> LoadPerImagePoseFile(const std::string& path) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(path);
  MapReader root(doc->root, "", &problems);
  Rigid3 pose;
  bool ok = root.ok();
  if (ok) {
    const bool visp = doc->root.Find("rows") || doc->root.Find("cols") || doc->root.Find("data");
    ok = visp ? ReadVispPose(&root, &problems, &pose) : ReadRosPose(&root, &problems, &pose);
  }
  root.Finish();
  if (!ok || !problems.empty()) {
    return problems.ToStatus("a pose (ROS x, y, z, qx, qy, qz, qw or ViSP vpPoseVector rows, cols, data)");
  }
  return pose;
}

Result<std::vector<ImagePose>> LoadPosesList(const std::string& path, const RobotModel* robot) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(path);
  MapReader root(doc->root, "", &problems);
  if (!CheckFormatAndVersion(&root, kPosesListFormat, kPosesListVersion)) {
    root.Abandon();
    return problems.ToStatus("a poses list");
  }
  std::vector<ImagePose> poses;
  if (const yaml::YamlNode* list = root.Required("poses")) {
    if (!list->IsSequence() || list->items.empty()) {
      problems.Add("`poses` at " + problems.At(list->line) + " must be a non-empty list of {image, base_from_flange"
                   " or joints_deg}");
    } else {
      for (size_t i = 0; i < list->items.size(); ++i) {
        ImagePose pose;
        if (ReadListEntry(list->items[i], "poses[" + std::to_string(i) + "]", robot, &problems, &pose)) {
          poses.push_back(std::move(pose));
        }
      }
    }
  }
  root.Finish();
  if (!problems.empty()) return problems.ToStatus("a poses list");
  return poses;
}

Status SavePosesList(const std::vector<PosesListEntry>& entries, const std::string& path) {
  if (entries.empty()) return Status::Error(ErrorCode::kInvalidInput, path + ": a poses list needs at least one pose");
  std::ostringstream out;
  out << "# Robot poses of a folder of images (docs/detect.md), for selfcal detect --poses\n"
      << "format: " << kPosesListFormat << "\nversion: " << kPosesListVersion << "\nposes:\n";
  for (size_t i = 0; i < entries.size(); ++i) {
    const PosesListEntry& e = entries[i];
    if (e.image.empty() || !e.joints_rad.allFinite() || e.joints_rad.size() == 0) {
      return Status::Error(ErrorCode::kInvalidInput, path + ": pose " + std::to_string(i) +
                                                         " needs an image name and finite joint angles");
    }
    out << "  - {image: " << YamlQuoted(e.image) << ", joints_rad: " << YamlNumberList(e.joints_rad)
        << (e.verification ? ", role: verification" : "") << "}\n";
  }
  return WriteFileAtomically(path, out.str());
}

Result<std::vector<ImagePose>> LoadImagePoses(const std::string& spec, const RobotModel* robot,
                                              const PoseReadOptions& options) {
  std::vector<ImagePose> poses;
  if (!IsDirectory(spec) && !HasGlobCharacters(spec)) {
    if (IsJson(spec)) {
      return Status::Error(ErrorCode::kInvalidInput,
                           spec + ": is the pose of one image; give the directory or a glob of every image's pose "
                                  "file (--poses DIR or 'DIR/pose_*.json')");
    }
    Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(spec);
    if (!doc.ok()) return doc.status();
    const yaml::YamlNode& root = doc->root;
    if (root.IsMap() && root.Find("format") == nullptr &&
        (root.Find("qw") || root.Find("x") || root.Find("rows") || root.Find("data"))) {
      return Status::Error(ErrorCode::kInvalidInput,
                           spec + ": is the pose of one image; give the directory or a glob of every image's pose "
                                  "file (--poses DIR or 'DIR/pose_*.yaml'), or one selfcal-poses list");
    }
    Result<std::vector<ImagePose>> list = LoadPosesList(spec, robot);
    if (!list.ok()) return list.status();
    poses = std::move(*list);
    for (ImagePose& pose : poses) {
      if (Status s = ToolToFlange(options, &pose); !s.ok()) return s;
    }
  } else {
    Result<std::vector<std::string>> files = ListFiles(spec, PoseFileExtensions(), "pose files");
    if (!files.ok()) return files.status();
    for (const std::string& file : *files) {
      Result<ImagePose> pose = LoadPoseFile(file, robot, options);
      if (!pose.ok()) return pose.status();
      poses.push_back(std::move(*pose));
    }
  }
  std::map<std::string, std::string> seen;  // key -> source
  for (const ImagePose& p : poses) {
    const auto [it, inserted] = seen.emplace(p.key, p.source);
    if (!inserted) {
      return Status::Error(ErrorCode::kInvalidInput, p.source + ": a second pose for image number `" + p.key +
                                                         "` (the first is " + it->second + ")");
    }
  }
  return poses;
}

Result<std::vector<ImagePose>> MatchPosesToImages(const std::vector<std::string>& image_paths,
                                                  const std::vector<ImagePose>& poses) {
  std::map<std::string, const ImagePose*> by_key;
  for (const ImagePose& p : poses) by_key.emplace(p.key, &p);
  std::map<std::string, std::string> image_of_key;
  std::vector<ImagePose> matched;
  std::string problems;
  for (const std::string& image : image_paths) {
    const std::string key = ImageKey(image);
    const auto [it, inserted] = image_of_key.emplace(key, image);
    if (!inserted) {
      problems += "\n  - " + image + ": has the same number `" + key + "` as " + it->second +
                  " (images are matched to poses by the last number in their names)";
      continue;
    }
    const auto pose = by_key.find(key);
    if (pose == by_key.end()) {
      problems += "\n  - " + image + ": no pose for image number `" + key + "`";
      continue;
    }
    matched.push_back(*pose->second);
  }
  for (const ImagePose& p : poses) {
    if (image_of_key.count(p.key) == 0) problems += "\n  - " + p.source + ": a pose for image number `" + p.key +
                                                    "`, but there is no such image";
  }
  if (!problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "images and poses do not match:" + problems);
  }
  return matched;
}

Result<ImagesAndPoses> LoadImagesAndPoses(const std::string& images_spec, const std::string& poses_spec,
                                          const RobotModel* robot, const PoseReadOptions& options) {
  ImagesAndPoses out;
  if (IsPoseFolderDirectory(images_spec)) {
    if (!poses_spec.empty() && std::filesystem::path(poses_spec).lexically_normal() !=
                                   std::filesystem::path(images_spec).lexically_normal()) {
      return Status::Error(ErrorCode::kInvalidInput,
                           images_spec + " holds a folder per pose, each with its image and pose file: leave out "
                                         "--poses " + poses_spec);
    }
    Result<std::vector<PoseFolder>> folders = ListPoseFolders(images_spec);
    if (!folders.ok()) return folders.status();
    for (const PoseFolder& folder : *folders) {
      Result<ImagePose> pose = LoadPoseFile(folder.pose_file, robot, options);
      if (!pose.ok()) return pose.status();
      out.images.push_back(folder.image);
      out.ids.push_back(folder.id);
      out.poses.push_back(std::move(*pose));
    }
    return out;
  }
  if (poses_spec.empty()) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--poses is required unless --images is a directory of one folder per pose (DIR/<id>/image + "
                         "pose file); " + images_spec + " is not");
  }
  Result<std::vector<std::string>> paths = ListFiles(images_spec, ImageExtensions(), "images");
  if (!paths.ok()) return paths.status();
  Result<std::vector<ImagePose>> poses = LoadImagePoses(poses_spec, robot, options);
  if (!poses.ok()) return poses.status();
  Result<std::vector<ImagePose>> matched = MatchPosesToImages(*paths, *poses);
  if (!matched.ok()) return matched.status();
  out.images = std::move(*paths);
  for (const std::string& image : out.images) out.ids.push_back(FileStem(image));
  out.poses = std::move(*matched);
  return out;
}

}  // namespace selfcal::io
