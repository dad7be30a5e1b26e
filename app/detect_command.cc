// selfcal detect: a folder of images and the robot pose of each -> an observations file (docs/detect.md).
// Parse -> io (image list, grey images, poses, robot, hand-eye) -> detection (points by id, the
// ObservationSet, the contact sheet) -> io (the observations file; the sheet through base/atomic_file.h;
// with --skip-failed the list of the images left out). Nothing is written unless everything succeeded, but
// for the contact sheet of a detection that failed (exit 3): it shows each image's reason.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/run_configuration.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "base/atomic_file.h"
#include "detection/contact_sheet.h"
#include "detection/detect_points.h"
#include "detection/grid_orientation.h"
#include "io/camera_file.h"
#include "io/file_lists.h"
#include "io/hand_eye_file.h"
#include "io/image_files.h"
#include "io/observations_file.h"
#include "io/plausible_limits.h"
#include "io/pose_files.h"
#include "io/robot_config.h"
#include "io/skipped_images_file.h"
#include "io/transform_yaml.h"
#include "rosbag/bag_images.h"

namespace selfcal::app {

namespace {

struct DetectSettings {
  std::string images, poses, out, contact_sheet;
  std::string bag;             // --bag: a ROS 2 recording instead of --images and --poses
  rosbag::BagOptions bag_options;
  std::string detector = "dots", identity = "grid", grid, polarity = "dark";
  bool asymmetric = false;  // circles: OpenCV's asymmetric grid
  std::string dictionary, board;  // charuco: the markers' dictionary and the board's squares ROWSxCOLS
  std::string robot, hand_eye;
  std::string configuration = "eye_in_hand";  // or eye_to_hand: the camera fixed, the points on the flange
  double fx_px = 0, cx_px = NAN, cy_px = NAN, mu = 1.0, k1 = 0.0;
  std::string camera_file, camera_name;  // instead of the --camera-* values
  bool camera_values_given = false;      // any --camera-fx-px, -cx-px, -cy-px, -mu, -k1
  double pixel_noise_px = 0.5;
  double flange_noise_mm = 0, flange_noise_deg = 0;  // --flange-pose-noise-mm / -deg (0: exact poses)
  std::vector<double> yardstick;  // A, B, length_mm
  double tag_side_mm = 0;
  std::vector<double> tag_dots_mm;
  double tag_tolerance_px = 3.0;
  int sheet_tile_px = 640;
  bool skip_failed = false;
  std::string scene;                        // --scene: every pose's scene (a recording of its own)
  std::string skipped_out;                  // --skipped-out, default SkippedListPath(out) with --skip-failed
  io::JsonPoseKeys json;                    // --pose-*-key: the keys of JSON pose files
  std::string joints_unit = "rad", matrix_order = "row", quaternion_order = "xyzw";
  std::vector<double> flange_from_tool;     // --flange-from-tool-mm-deg X,Y,Z,ROLL,PITCH,YAW
};

Status Usage(const std::string& message) { return Status::Error(ErrorCode::kInvalidInput, message); }

// "ROWSxCOLS", e.g. "6x9".
Status ParseGrid(const std::string& text, int* rows, int* cols) {
  const size_t x = text.find_first_of("xX");
  int r = 0, c = 0;
  char tail = 0;
  if (x == std::string::npos || std::sscanf(text.c_str(), "%d", &r) != 1 ||
      std::sscanf(text.c_str() + x + 1, "%d%c", &c, &tail) != 1 || r < 2 || c < 2 || r > 1000 || c > 1000) {
    return Usage("--grid `" + text + "`: ROWSxCOLS expected, e.g. 10x10 (dot grid) or 6x9 (chessboard inner corners)");
  }
  *rows = r;
  *cols = c;
  return Status::Ok();
}

Result<detection::DetectionOptions> ToDetectionOptions(const DetectSettings& a) {
  detection::DetectionOptions o;
  Result<detection::Detector> detector = detection::ParseDetector(a.detector);
  if (!detector.ok()) return detector.status();
  Result<detection::Identity> identity = detection::ParseIdentity(a.identity);
  if (!identity.ok()) return identity.status();
  o.detector = *detector;
  o.identity = *identity;
  if (a.grid.empty() && o.detector == detection::Detector::kChessboard) {
    return Usage("--detector chessboard needs --grid ROWSxCOLS (inner corners, e.g. 6x9)");
  }
  if (a.grid.empty() && o.detector == detection::Detector::kCircles) {
    return Usage("--detector circles needs --grid ROWSxCOLS (rows of dots x dots per row, e.g. 11x4 --asymmetric)");
  }
  Result<detection::Polarity> polarity = detection::ParsePolarity(a.polarity);
  if (!polarity.ok()) return polarity.status();
  o.polarity = *polarity;
  o.asymmetric = a.asymmetric;
  const bool charuco = o.detector == detection::Detector::kCharuco;
  if (charuco != !a.board.empty() || charuco != !a.dictionary.empty() || (charuco && !a.grid.empty())) {
    return Usage("--detector charuco takes --dictionary NAME and --board XxY (squares, e.g. 5x7) instead of --grid; "
                 "--dictionary and --board apply to charuco only");
  }
  if (!a.grid.empty()) {
    if (Status s = ParseGrid(a.grid, &o.rows, &o.cols); !s.ok()) return s;
  }
  if (charuco) {
    // OpenCV's squaresX x squaresY: the columns first.
    if (!ParseGrid(a.board, &o.cols, &o.rows).ok()) {
      return Usage("--board `" + a.board + "`: XxY expected, the board's squares along its x and y as OpenCV's "
                   "CharucoBoard takes them, e.g. 5x7");
    }
    o.charuco.dictionary = a.dictionary;
  }
  o.tag_side_m = a.tag_side_mm * 1e-3;
  if (a.tag_dots_mm.size() % 2 != 0) return Usage("--tag-dots-mm: x,y pairs expected");
  for (size_t k = 0; k + 1 < a.tag_dots_mm.size(); k += 2) {
    o.tag_dots_m.emplace_back(a.tag_dots_mm[k] * 1e-3, a.tag_dots_mm[k + 1] * 1e-3);
  }
  o.tag_tolerance_px = a.tag_tolerance_px;
  if (Status s = o.Validate(); !s.ok()) return Usage("detector options:\n" + s.message());
  return o;
}

// Camera, noise, yardstick, robot and hand-eye of the set.
Result<detection::ObservationSetup> ToSetup(const DetectSettings& a, const vpImage<unsigned char>& first,
                                            const RobotModel* robot) {
  detection::ObservationSetup setup;
  if (robot != nullptr) setup.robot = *robot;
  const int width = static_cast<int>(first.getWidth()), height = static_cast<int>(first.getHeight());
  if (!a.camera_file.empty()) {
    Result<CameraIntrinsics> camera = io::LoadCameraFile(a.camera_file, a.camera_name);
    if (!camera.ok()) return camera.status();
    if (camera->width_px != width || camera->height_px != height) {
      return Usage("camera file " + a.camera_file + " is for " + std::to_string(camera->width_px) + "x" +
                   std::to_string(camera->height_px) + " images, the images are " + std::to_string(width) + "x" +
                   std::to_string(height));
    }
    setup.camera = *camera;
  } else {
    setup.camera.width_px = width;
    setup.camera.height_px = height;
    setup.camera.fx_px = a.fx_px;
    setup.camera.cx_px = std::isnan(a.cx_px) ? 0.5 * (width - 1) : a.cx_px;
    setup.camera.cy_px = std::isnan(a.cy_px) ? 0.5 * (height - 1) : a.cy_px;
    setup.camera.mu = a.mu;
    setup.camera.k1 = a.k1;
    if (const std::string problems = setup.camera.Validate(); !problems.empty()) {
      return Usage("--camera-* options:\n" + problems);
    }
  }
  setup.pixel_noise_px = a.pixel_noise_px;
  if ((a.flange_noise_mm > 0) != (a.flange_noise_deg > 0)) {
    return Usage("--flange-pose-noise-mm and --flange-pose-noise-deg: give both (the flange poses' stated noise) or "
                 "neither (exact poses)");
  }
  setup.flange_translation_sigma_m = a.flange_noise_mm * 1e-3;
  setup.flange_rotation_sigma_rad = DegToRad(a.flange_noise_deg);
  if (!a.yardstick.empty()) {
    const bool ints = a.yardstick.size() == 3 && a.yardstick[0] >= 0 && a.yardstick[1] >= 0 &&
                      a.yardstick[0] == std::floor(a.yardstick[0]) && a.yardstick[1] == std::floor(a.yardstick[1]);
    if (!ints || !(a.yardstick[2] >= io::kMinKnownDistanceM * 1e3 && a.yardstick[2] <= io::kMaxKnownDistanceM * 1e3)) {
      return Usage("--yardstick A,B,LENGTH_MM: two point ids and their distance in [1, 100000] mm");
    }
    setup.yardsticks.push_back({static_cast<int>(a.yardstick[0]), static_cast<int>(a.yardstick[1]), a.yardstick[2] * 1e-3});
  }
  if (!ParseCameraMount(a.configuration, &setup.mount)) {
    return Usage("--configuration " + a.configuration + ": eye_in_hand or eye_to_hand");
  }
  if (!a.hand_eye.empty()) {
    Result<io::HandEyeResult> hand_eye = io::LoadHandEye(a.hand_eye);
    if (!hand_eye.ok()) return hand_eye.status();
    if (hand_eye->mount != setup.mount) {
      return Usage("--hand-eye " + a.hand_eye + " is an " + CameraMountName(hand_eye->mount) + " result; this set is " +
                   CameraMountName(setup.mount) + " (--configuration)");
    }
    if (setup.mount == CameraMount::kEyeToHand) {
      setup.base_from_cam = hand_eye->base_from_cam;
    } else {
      setup.flange_from_cam = hand_eye->flange_from_cam;
    }
  }
  setup.skip_failed = a.skip_failed;
  return setup;
}

// The pose files' reading: JSON keys, and the tool frame (mm and deg on the command line, SI inside).
Result<io::PoseReadOptions> ToPoseReadOptions(const DetectSettings& a) {
  io::PoseReadOptions o;
  o.json = a.json;
  o.json.joints_deg = a.joints_unit == "deg";
  o.json.column_major = a.matrix_order == "column";
  o.json.quaternion_wxyz = a.quaternion_order == "wxyz";
  if (!o.json.empty()) {
    if (Status s = o.json.Validate(); !s.ok()) return Usage(s.message());
  }
  if (!a.flange_from_tool.empty()) {
    const std::vector<double>& v = a.flange_from_tool;
    o.flange_from_tool = Rigid3(io::RotationFromRpy(DegToRad(v[3]), DegToRad(v[4]), DegToRad(v[5])),
                                Eigen::Vector3d(v[0], v[1], v[2]) * 1e-3);
  }
  return o;
}

// A rotation made orthonormal is said per pose, on stderr: what was read is not what the file holds.
void ReportRotationCorrections(const io::ImagesAndPoses& inputs) {
  for (size_t i = 0; i < inputs.poses.size(); ++i) {
    const io::ImagePose& p = inputs.poses[i];
    if (p.rotation_correction_rad > 0) {
      std::cerr << "selfcal: note: " << io::RotationCorrectionNote(p.source, inputs.ids[i], p.rotation_correction_rad) << "\n";
    }
  }
}

// An image without points is FAILED, or SKIPPED when --skip-failed leaves it out of a set that was built.
void PrintPerImage(const std::vector<io::NamedImage>& images, const std::vector<detection::ImagePoints>& points,
                   const std::string& failed_label) {
  for (size_t i = 0; i < images.size(); ++i) {
    std::cout << (points[i].ok ? "  " : "  " + failed_label + " ") << images[i].path << ": " << points[i].message << "\n";
  }
}

// Where --skip-failed lists the images it left out, unless --skipped-out: beside the observations file,
// OBS.yaml -> OBS.skipped.yaml.
std::string SkippedListPath(const DetectSettings& a) {
  if (!a.skipped_out.empty() || !a.skip_failed || a.out.empty()) return a.skipped_out;
  for (const std::string ext : {".yaml", ".yml"}) {
    if (a.out.size() > ext.size() && a.out.compare(a.out.size() - ext.size(), ext.size(), ext) == 0) {
      return a.out.substr(0, a.out.size() - ext.size()) + ".skipped.yaml";
    }
  }
  return a.out + ".skipped.yaml";
}

// --contact-sheet: every image, its points, and the reason of each image without them.
Status WriteContactSheet(const DetectSettings& a, const detection::DetectionOptions& options,
                         const std::vector<std::string>& ids, const std::vector<const vpImage<unsigned char>*>& pixels,
                         const std::vector<detection::ImagePoints>& points, const std::string& failed_label) {
  std::vector<detection::SheetImage> sheet;
  for (size_t i = 0; i < pixels.size(); ++i) sheet.push_back({ids[i], pixels[i], &points[i]});
  detection::ContactSheetOptions so;
  so.max_tile_width_px = a.sheet_tile_px;
  so.failed_label = failed_label;
  if (options.identity == detection::Identity::kGrid && options.detector != detection::Detector::kAprilTag) {
    // A ChArUco board of cols squares has cols - 1 corners a row.
    so.grid_cols = options.detector == detection::Detector::kCharuco ? options.cols - 1 : options.cols;
  }
  Result<std::string> png = detection::ContactSheetPng(sheet, so);
  if (!png.ok()) return png.status();
  return WriteFileAtomically(a.contact_sheet, *png);
}

// --skip-failed: the images left out, on stdout and in the skipped list.
Status WriteSkippedList(const DetectSettings& a, const std::vector<io::NamedImage>& images,
                        const std::vector<std::string>& ids, const std::vector<detection::ImagePoints>& points,
                        const ObservationSet& set) {
  io::SkippedImages list;
  list.observations = a.out;
  list.images = static_cast<int>(images.size());
  list.kept = static_cast<int>(set.poses.size());
  for (size_t i = 0; i < images.size(); ++i) {
    if (points[i].ok && !points[i].points_px.empty()) continue;
    list.skipped.push_back({ids[i], images[i].path, points[i].message.empty() ? "no point found" : points[i].message});
  }
  const std::string path = SkippedListPath(a);
  if (Status s = io::SaveSkippedImages(list, path); !s.ok()) return s;
  std::printf("skipped %zu of %zu images, listed in %s\n", list.skipped.size(), images.size(), path.c_str());
  AddOutputFile("skipped_images", path);
  return Status::Ok();
}

// --json: images and points, per image and in all.
void RecordDetectFigures(const std::vector<io::NamedImage>& images, const std::vector<detection::ImagePoints>& points,
                         const ObservationSet& set) {
  nlohmann::json per_image = nlohmann::json::array();
  for (size_t i = 0; i < images.size(); ++i) {
    per_image.push_back({{"image", images[i].path},
                         {"ok", points[i].ok},
                         {"points", points[i].ok ? points[i].points_px.size() : 0},
                         {"message", points[i].message}});
  }
  size_t total = 0;
  for (const PoseObservation& p : set.poses) total += p.dots_px.size();
  OutputDocument()["detect"] = {{"images", images.size()},
                                {"images_with_points", set.poses.size()},
                                {"points", total},
                                {"poses", set.UsesFlangePoses() ? "flange" : "joint"},
                                {"configuration", CameraMountName(set.robot.mount)},
                                {"per_image", per_image}};
}

// The images and their poses: a folder and its poses (io), or a ROS 2 bag's still images (rosbag).
Status LoadInputs(const DetectSettings& a, const RobotModel* robot, io::ImagesAndPoses* inputs,
                  std::vector<io::NamedImage>* images) {
  if (a.bag.empty() == a.images.empty()) return Usage("give --images (a folder of images) or --bag (a ROS 2 recording)");
  if (!a.bag.empty()) {
    if (!a.poses.empty() || !a.json.empty()) return Usage("--bag " + a.bag + " gives the joint angles: leave out --poses and --pose-*-key");
    if (robot == nullptr || a.bag_options.image_topic.empty()) return Usage("--bag needs --robot and --image-topic");
    Result<rosbag::BagImages> bag = rosbag::LoadBagImagesForRobot(a.bag, a.bag_options, ResolveDataPath(a.robot), *robot);
    if (!bag.ok()) return bag.status();
    for (const std::string& note : bag->notes) std::cerr << "selfcal: note: " << note << "\n";
    std::printf("%zu of %d images on %s taken while the arm was still (%d while moving left out)\n", bag->images.size(),
                bag->image_messages, a.bag_options.image_topic.c_str(), bag->moving);
    *inputs = std::move(bag->inputs);
    *images = std::move(bag->images);
    return Status::Ok();
  }
  Result<io::PoseReadOptions> pose_options = ToPoseReadOptions(a);
  if (!pose_options.ok()) return pose_options.status();
  Result<io::ImagesAndPoses> listed = io::LoadImagesAndPoses(a.images, a.poses, robot, *pose_options);
  if (!listed.ok()) return listed.status();
  ReportRotationCorrections(*listed);
  Result<std::vector<io::NamedImage>> read = io::ReadGreyImages(listed->images);
  if (!read.ok()) return read.status();
  *inputs = std::move(*listed);
  *images = std::move(*read);
  return Status::Ok();
}

int DetectFromSettings(const DetectSettings& a) {
  const auto start = std::chrono::steady_clock::now();
  Result<detection::DetectionOptions> options = ToDetectionOptions(a);
  if (!options.ok()) return Fail(options.status());
  if (!a.camera_file.empty() && a.camera_values_given) {
    return Fail(Usage("--camera-file " + a.camera_file + " gives the intrinsics: leave out --camera-fx-px, --camera-cx-px, "
                      "--camera-cy-px, --camera-mu and --camera-k1"));
  }
  if (a.camera_file.empty() && !a.camera_name.empty()) {
    return Fail(Usage("--camera-name " + a.camera_name + " selects a camera of a --camera-file; none was given"));
  }
  if (!a.skipped_out.empty() && !a.skip_failed) {
    return Fail(Usage("--skipped-out " + a.skipped_out + " lists the images --skip-failed leaves out; give --skip-failed"));
  }
  if (a.camera_file.empty() && !(a.fx_px > 0)) {
    return Fail(Usage("--camera-fx-px (the camera's nominal focal length, px) or --camera-file is required"));
  }
  std::unique_ptr<RobotModel> robot;
  if (!a.robot.empty()) {
    Result<RobotModel> loaded = io::LoadRobotModel(ResolveDataPath(a.robot));
    if (!loaded.ok()) return Fail(loaded.status());
    robot = std::make_unique<RobotModel>(*loaded);
  }
  io::ImagesAndPoses inputs_read;
  std::vector<io::NamedImage> images_read;
  if (Status s = LoadInputs(a, robot.get(), &inputs_read, &images_read); !s.ok()) return Fail(s);
  const io::ImagesAndPoses* inputs = &inputs_read;
  const std::vector<io::NamedImage>* images = &images_read;
  const std::vector<io::ImagePose>& matched = inputs->poses;
  Result<detection::ObservationSetup> setup = ToSetup(a, images->front().image, robot.get());
  if (!setup.ok()) return Fail(setup.status());

  std::vector<const vpImage<unsigned char>*> pixels;
  std::vector<std::string> ids;
  std::vector<detection::ImageRobotPose> robot_poses;
  for (size_t i = 0; i < images->size(); ++i) {
    pixels.push_back(&(*images)[i].image);
    ids.push_back(inputs->ids[i]);
    robot_poses.push_back({matched[i].base_from_flange, matched[i].joints_rad,
                           matched[i].verification ? PoseRole::kVerification : PoseRole::kIdentification});
  }
  detection::DetectionOptions detect_options = *options;
  detect_options.progress = Progress();
  std::vector<detection::ImagePoints> points = detection::DetectAllImagePoints(pixels, detect_options);
  detection::OrientCircleGrids(detect_options, robot_poses, *setup, &points);
  detection::ObservationSetup with_tags = *setup;
  if (options->detector == detection::Detector::kAprilTag && options->tag_side_m > 0) {
    // The tags' known side: each tag's bottom edge a yardstick, its top edge a check distance.
    const detection::TagEdges edges = detection::TagEdgeDistances(points, options->tag_side_m);
    with_tags.yardsticks.insert(with_tags.yardsticks.end(), edges.yardsticks.begin(), edges.yardsticks.end());
    with_tags.check_distances = edges.check_distances;
  }
  Result<ObservationSet> set = detection::BuildObservationSet(ids, points, robot_poses, with_tags);
  // A detection that failed (kDegenerateData) still gets its contact sheet: each image's reason, for a person.
  const bool detection_failed = !set.ok() && set.status().code() == ErrorCode::kDegenerateData;
  PrintPerImage(*images, points, set.ok() ? "SKIPPED" : "FAILED");
  if (!set.ok() && !detection_failed) return Fail(set.status());
  if (!a.contact_sheet.empty()) {
    if (Status s = WriteContactSheet(a, *options, ids, pixels, points, set.ok() ? "SKIPPED" : "FAILED"); !s.ok()) {
      return Fail(s);
    }
    if (detection_failed) std::cerr << "selfcal: each image's outcome is on the contact sheet " << a.contact_sheet << "\n";
  }
  if (detection_failed) return Fail(set.status());
  for (PoseObservation& pose : set.value().poses) pose.scene = a.scene;
  Status written = io::SaveObservations(*set, a.out);
  if (written.ok() && a.skip_failed) {
    written = WriteSkippedList(a, *images, ids, points, *set);
    if (!written.ok()) std::remove(a.out.c_str());
  }
  if (!written.ok()) {
    if (!a.contact_sheet.empty()) std::remove(a.contact_sheet.c_str());  // nothing is left on an error
    return Fail(written);
  }
  size_t fewest = SIZE_MAX, most = 0;
  for (const PoseObservation& p : set->poses) {
    fewest = std::min(fewest, p.dots_px.size());
    most = std::max(most, p.dots_px.size());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordDetectFigures(*images, points, *set);
  AddOutputFile("observations", a.out);
  if (!a.contact_sheet.empty()) AddOutputFile("contact_sheet", a.contact_sheet);
  std::printf("%zu of %zu images with points (%zu to %zu points each), %s poses, %s; wrote %s%s%s (%.2f s)\n",
              set->poses.size(), images->size(), fewest, most, set->UsesFlangePoses() ? "flange" : "joint",
              CameraMountName(set->robot.mount),
              a.out.c_str(), a.contact_sheet.empty() ? "" : " and ", a.contact_sheet.c_str(), seconds);
  return 0;
}

}  // namespace

Command AddDetectCommand(CLI::App& app) {
  auto a = std::make_shared<DetectSettings>();
  CLI::App* cmd = app.add_subcommand(
      "detect", "Detect and name the points of a folder of images and write an observations file (docs/detect.md)");
  cmd->add_option("--images", a->images, "Directory of images (png, jpg, pgm, ...) or a glob ('shots/img_*.png')");
  cmd->add_option("--bag", a->bag, "A ROS 2 recording (rosbag2 .mcap) instead of --images and --poses: the images "
                  "taken while the arm was still, with the joint states nearest in time (needs --robot, --image-topic)");
  cmd->add_option("--image-topic", a->bag_options.image_topic,
                  "--bag: the topic of the images (sensor_msgs/msg/Image or CompressedImage)");
  cmd->add_option("--joint-topic", a->bag_options.joint_topic, "--bag: the joint states' topic (default /joint_states)");
  cmd->add_option("--poses", a->poses,
                  "Robot poses: a directory or glob of per-image files (ROS x,y,z,qx..qw, ViSP vpPoseVector, or JSON "
                  "with --pose-*-key), or a selfcal-poses list; not needed when --images holds a folder per pose");
  cmd->add_option("--pose-joints-key", a->json.joints, "JSON pose files: the key of the joint angles");
  cmd->add_option("--pose-joints-unit", a->joints_unit, "JSON pose files: the joint angles' unit, rad (default) or deg")
      ->check(CLI::IsMember({"rad", "deg"}));
  cmd->add_option("--pose-matrix-key", a->json.matrix,
                  "JSON pose files: the key of a 4x4 pose (16 numbers or 4 rows of 4, m) of the flange or the tool");
  cmd->add_option("--pose-matrix-order", a->matrix_order,
                  "JSON pose files: the 16 numbers row by row (row, default) or column by column (column)")
      ->check(CLI::IsMember({"row", "column"}));
  cmd->add_option("--pose-position-key", a->json.position, "JSON pose files: the key of the position (3 numbers, m)");
  cmd->add_option("--pose-quaternion-key", a->json.quaternion, "JSON pose files: the key of the unit quaternion");
  cmd->add_option("--pose-quaternion-order", a->quaternion_order, "JSON pose files: xyzw (default) or wxyz")
      ->check(CLI::IsMember({"xyzw", "wxyz"}));
  cmd->add_option("--flange-from-tool-mm-deg", a->flange_from_tool,
                  "X,Y,Z,ROLL,PITCH,YAW: the recorded poses are of a tool (TCP) frame, whose pose in the flange frame "
                  "this is (mm; deg, R = Rz(yaw) Ry(pitch) Rx(roll)); they become flange poses")
      ->delimiter(',')
      ->expected(6);
  AddOutputOption(cmd, "--out", &a->out, OutputKind::kFile, "Observations file to write (docs/observations-format.md)")->required();
  AddOutputOption(cmd, "--contact-sheet", &a->contact_sheet, OutputKind::kFile,
                  "Also write every image with its points and ids as one PNG");
  cmd->add_option("--contact-sheet-tile-px", a->sheet_tile_px, "Largest thumbnail width on the contact sheet, px")
      ->check(CLI::Range(64, 8192));
  cmd->add_option("--detector", a->detector,
                  "dots, circles (a circle grid without an origin dot), chessboard, charuco or apriltag (the corners "
                  "of every AprilTag 36h11: id = tag id * 4 + corner; with --tag-side-mm a yardstick per tag)")
      ->check(CLI::IsMember({"dots", "circles", "chessboard", "charuco", "apriltag"}));
  cmd->add_option("--grid", a->grid, "ROWSxCOLS: the dot grid (default 10x10), the circle grid or the chessboard's inner corners");
  cmd->add_flag("--asymmetric", a->asymmetric, "circles: OpenCV's asymmetric grid (every other row shifted by half a step)");
  cmd->add_option("--polarity", a->polarity, "dots and circles: dark dots (default), light dots on a dark board, or auto")
      ->check(CLI::IsMember({"dark", "light", "auto"}));
  cmd->add_option("--dictionary", a->dictionary, "charuco: the markers' OpenCV dictionary, e.g. DICT_6X6_250");
  cmd->add_option("--board", a->board, "charuco: the board's squares XxY (OpenCV's squaresX x squaresY), e.g. 5x7");
  cmd->add_option("--identity", a->identity, "How dots are named: grid (larger origin dot), apriltag, order")
      ->check(CLI::IsMember({"grid", "apriltag", "order"}));
  cmd->add_option("--tag-side-mm", a->tag_side_mm,
                  "apriltag: outer side of the tags' black border, mm (the apriltag detector: its edges as yardstick "
                  "and check distance; 1 to 100000)")
      ->check(CLI::Range(io::kMinKnownDistanceM * 1e3, io::kMaxKnownDistanceM * 1e3))
      ->default_str("");  // 0: no tag side given
  cmd->add_option("--tag-dots-mm", a->tag_dots_mm, "apriltag: x1,y1,x2,y2,... of the dots around every tag, mm")
      ->delimiter(',');
  cmd->add_option("--tag-tolerance-px", a->tag_tolerance_px, "apriltag: a dot this close to its prediction is named")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--robot", a->robot, "Robot config (config/robots/*.yaml): needed for joint-angle poses");
  cmd->add_option("--hand-eye", a->hand_eye,
                  "A nominal camera transform (selfcal-hand-eye file): flange_from_cam for flange poses, or, with "
                  "--configuration eye_to_hand, the fixed camera base_from_cam");
  AddConfigurationOption(cmd, &a->configuration);
  cmd->add_option("--camera-file", a->camera_file,
                  "The camera's intrinsics from an OpenCV FileStorage or ViSP XML file (docs/camera-files.md), instead "
                  "of the --camera-* values");
  cmd->add_option("--camera-name", a->camera_name, "The camera of a ViSP --camera-file holding several");
  std::vector<CLI::Option*> values = {
      cmd->add_option("--camera-fx-px", a->fx_px, "The camera's nominal focal length, px")->check(CLI::PositiveNumber),
      cmd->add_option("--camera-cx-px", a->cx_px, "Principal point u, px (default: the image centre)")->default_str(""),
      cmd->add_option("--camera-cy-px", a->cy_px, "Principal point v, px (default: the image centre)")->default_str(""),
      cmd->add_option("--camera-mu", a->mu, "f_y / f_x (default 1)")->check(CLI::PositiveNumber),
      cmd->add_option("--camera-k1", a->k1, "Radial distortion k1 (default 0)")};
  cmd->add_option("--pixel-noise-px", a->pixel_noise_px, "Standard deviation of a point's pixel, px (default 0.5)")
      ->check(CLI::Range(kMinPixelNoisePx, kMaxPixelNoisePx));
  cmd->add_option("--flange-pose-noise-mm", a->flange_noise_mm,
                  "Flange poses: the stated noise of each recorded flange position, mm (with -deg; 0: exact)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--flange-pose-noise-deg", a->flange_noise_deg,
                  "Flange poses: the stated noise of each recorded flange rotation, deg (with -mm; 0: exact)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--yardstick", a->yardstick, "A,B,LENGTH_MM: a known distance between points A and B")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--scene", a->scene,
                  "Every pose sees this scene: a recording whose points are its own (a board that moved), for "
                  "observations pooled by hand with others (calibrate FIRST --also SECOND names each file's scene)")
      ->check([](const std::string& name) { return name.empty() ? std::string("an empty scene name") : std::string(); });
  cmd->add_flag("--skip-failed", a->skip_failed,
                "Leave images without points out instead of failing, and list them with their reasons (--skipped-out)");
  AddOutputOption(cmd, "--skipped-out", &a->skipped_out, OutputKind::kFile,
                  "With --skip-failed: the list of the images left out (default: beside --out, OBS.skipped.yaml)");
  SetOutputPathWhenEmpty(cmd, "--skipped-out", [a]() { return SkippedListPath(*a); });
  return [a, values]() {
    for (const CLI::Option* option : values) a->camera_values_given = a->camera_values_given || option->count() > 0;
    return DetectFromSettings(*a);
  };
}

}  // namespace selfcal::app
