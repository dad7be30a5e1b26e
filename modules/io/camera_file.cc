#include "io/camera_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <regex>
#include <sstream>
#include <vector>

#include <opencv2/core.hpp>
#include <visp3/core/vpXmlParserCamera.h>

#include "base/atomic_file.h"
#include "base/terminal_text.h"
#include "base/time_limited_child.h"
#include "io/camera_xml.h"
#include "io/opencv_lines.h"
#include "io/yaml_schema.h"

namespace selfcal::io {

namespace {

constexpr size_t kMaxCameraFileBytes = 16u << 20;

std::string Num(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  }
  return true;
}

// The closest of `allowed` to `key` as "; did you mean `x`?", or the list of allowed keys.
std::string Suggestion(const std::string& key, const std::vector<std::string>& allowed) {
  std::string best;
  int best_distance = 1 << 30;
  for (const std::string& candidate : allowed) {
    const int d = EditDistance(key, candidate);
    if (d < best_distance) best_distance = d, best = candidate;
  }
  const bool prefix = !best.empty() && key.size() >= 4 && best.compare(0, key.size() - 1, key, 0, key.size() - 1) == 0;
  if (!best.empty() && (prefix || best_distance <= std::max<int>(2, static_cast<int>(key.size()) / 3))) {
    return "; did you mean `" + best + "`?";
  }
  std::string list = "; allowed:";
  for (const std::string& candidate : allowed) list += " `" + candidate + "`";
  return list;
}

// The intrinsics' own checks (principal point inside the image, ...), one problem each, at the line of
// the key that holds the value (`at(key)`: "<file>:<line>").
template <typename At>
void AddValidation(const CameraIntrinsics& camera, const At& at, Problems* problems) {
  std::istringstream invalid(camera.Validate());
  for (std::string line; std::getline(invalid, line);) {
    const char* key = line.rfind("image size", 0) == 0               ? "image_width"
                      : line[0] == 'k' || line[0] == 'p'           ? "distortion_coefficients"
                                                                     : "camera_matrix";
    problems->Add("`" + std::string(key) + "` at " + at(key) + ": " + line);
  }
}

// --- OpenCV FileStorage -------------------------------------------------------------------------------

// Keys that OpenCV's calibration samples write beside the intrinsics; accepted and not used.
const std::vector<std::string> kOpenCvKeys = {
    "image_width", "image_height", "camera_matrix", "distortion_coefficients", "calibration_time", "calibrationDate",
    "nframes", "nr_of_frames", "board_width", "board_height", "square_size", "aspectRatio", "fix_aspect_ratio",
    "flags", "flagValue", "fisheye_model", "avg_reprojection_error", "per_view_reprojection_errors",
    "extrinsic_parameters", "image_points", "grid_points"};

bool ReadOpenCvInt(const cv::FileNode& node, const std::string& key, const std::string& file, Problems* problems,
                   int* out) {
  if (node.empty() || node.isNone()) {
    problems->Add("missing key `" + key + "` in the document at " + file);
    return false;
  }
  if (!node.isInt() || static_cast<int>(node) < 1 || static_cast<int>(node) > 100000) {
    problems->Add("`" + key + "` at " + file + " must be an integer in [1, 100000]");
    return false;
  }
  *out = static_cast<int>(node);
  return true;
}

bool ReadOpenCvMatrix(const cv::FileNode& node, const std::string& key, const std::string& file, Problems* problems,
                      cv::Mat* out) {
  if (node.empty() || node.isNone()) {
    problems->Add("missing key `" + key + "` in the document at " + file);
    return false;
  }
  // rows, cols and data checked before cv::FileStorage allocates rows x cols: a mistyped `cols` (or a
  // repeated key) can make it ask for tens of gigabytes. The intrinsics' matrices have at most 16 entries.
  const auto small_int = [](const cv::FileNode& n) { return n.isInt() && int(n) >= 1 && int(n) <= 16; };
  if (!node.isMap() || !small_int(node["rows"]) || !small_int(node["cols"]) || !node["data"].isSeq() ||
      node["data"].size() != static_cast<size_t>(int(node["rows"]) * int(node["cols"]))) {
    problems->Add("`" + key + "` at " + file + " must be an opencv-matrix (rows, cols, dt, data) of at most 16 " +
                  "entries, with rows x cols values in data");
    return false;
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const std::exception& e) {  // cv::Exception, or a std::exception of FileStorage
    m = cv::Mat();
  }
  if (m.empty() || m.channels() != 1) {
    problems->Add("`" + key + "` at " + file + " must be an opencv-matrix (rows, cols, dt, data)");
    return false;
  }
  m.convertTo(*out, CV_64F);
  for (int r = 0; r < out->rows; ++r) {
    for (int c = 0; c < out->cols; ++c) {
      if (!std::isfinite(out->at<double>(r, c))) {
        problems->Add("`" + key + "` at " + file + " has a non-finite entry");
        return false;
      }
    }
  }
  return true;
}

// K = [fx 0 cx; 0 fy cy; 0 0 1] exactly (no skew: selfcal's model has none).
void ReadCameraMatrix(const cv::Mat& k, const std::string& file, Problems* problems, CameraIntrinsics* camera) {
  if (k.rows != 3 || k.cols != 3) {
    problems->Add("`camera_matrix` at " + file + " is " + std::to_string(k.rows) + "x" + std::to_string(k.cols) +
                  ", must be 3x3");
    return;
  }
  if (k.at<double>(0, 1) != 0) {
    problems->Add("`camera_matrix` at " + file + " has skew " + Num(k.at<double>(0, 1)) +
                  " (entry [0][1]); selfcal's camera model has none and cannot represent it");
  }
  if (k.at<double>(1, 0) != 0 || k.at<double>(2, 0) != 0 || k.at<double>(2, 1) != 0 || k.at<double>(2, 2) != 1) {
    problems->Add("`camera_matrix` at " + file + " must be [fx 0 cx; 0 fy cy; 0 0 1]");
  }
  camera->fx_px = k.at<double>(0, 0);
  camera->cx_px = k.at<double>(0, 2);
  camera->cy_px = k.at<double>(1, 2);
  if (!(camera->fx_px > 0) || !(k.at<double>(1, 1) > 0)) {
    problems->Add("`camera_matrix` at " + file + ": fx and fy must be > 0");
    return;
  }
  camera->mu = k.at<double>(1, 1) / camera->fx_px;
}

// OpenCV's order k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx, ty]]]]: the terms after k3 must be zero.
void ReadDistortion(const cv::Mat& d, const std::string& file, Problems* problems, CameraIntrinsics* camera) {
  const int n = static_cast<int>(d.total());
  if ((d.rows != 1 && d.cols != 1) || (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
    problems->Add("`distortion_coefficients` at " + file + " is " + std::to_string(d.rows) + "x" +
                  std::to_string(d.cols) + ", must be a vector of 4, 5, 8, 12 or 14 coefficients");
    return;
  }
  const double* v = d.ptr<double>();
  camera->k1 = v[0];
  camera->k2 = v[1];
  camera->p1 = v[2];
  camera->p2 = v[3];
  camera->k3 = n >= 5 ? v[4] : 0.0;
  for (int i = 5; i < n; ++i) {
    if (v[i] == 0) continue;
    const char* model = i < 8 ? "rational (k4, k5, k6)" : i < 12 ? "thin-prism (s1..s4)" : "tilted-sensor (tau_x, tau_y)";
    problems->Add("`distortion_coefficients` at " + file + ": coefficient " + std::to_string(i) + " = " + Num(v[i]) +
                  " belongs to OpenCV's " + model + " model, which selfcal cannot represent");
  }
}

// The text could not be read as FileStorage: OpenCV's reason at the line its parser names, else line 1
// (an empty file, an unknown header).
Status OpenCvReadError(const std::string& path, const std::string& what) {
  const std::optional<OpenCvParseError> parsed = ParseOpenCvError(what);
  const std::string reason = parsed ? parsed->reason : what;
  return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as an OpenCV FileStorage file: " + path +
                                                     ":" + std::to_string(parsed ? parsed->line : 1) + ": " +
                                                     TerminalSafe(reason));
}

// OpenCV 4.6's YAML reader loops forever on some texts whose first line is a malformed `%YAML` directive
// (found by the camera_opencv fuzz harness): such a line is refused before OpenCV sees the text. The
// directive OpenCV writes is `%YAML:1.0`; `%YAML 1.x` is the YAML standard's.
bool MalformedYamlDirective(const std::string& contents) {
  if (contents.rfind("%YAML", 0) != 0) return false;
  const std::string line = contents.substr(0, contents.find('\n'));
  static const std::regex directive(R"(%YAML[: ]1\.[0-9]+[ \t\r]*)");
  return !std::regex_match(line, directive);
}

Result<CameraIntrinsics> LoadOpenCv(const std::string& path, const std::string& contents) {
  Problems problems(path);
  if (MalformedYamlDirective(contents)) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as an OpenCV FileStorage file: " + path +
                                                       ":1: the first line must be the directive `%YAML:1.0` (found `" +
                                                       TerminalSafe(contents.substr(0, std::min<size_t>(contents.find('\n'), 60))) + "`)");
  }
  // A second `%YAML` directive inside the document hangs that reader too (found by the fuzzer after the
  // first fix); a camera file has one, on its first line.
  if (const size_t again = contents.find("%YAML", 1); again != std::string::npos && contents.rfind("%YAML", 0) == 0) {
    const long line = 1 + std::count(contents.begin(), contents.begin() + static_cast<long>(again), '\n');
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as an OpenCV FileStorage file: " + path +
                                                       ":" + std::to_string(line) +
                                                       ": a second `%YAML` directive inside the document");
  }
  cv::FileStorage fs;
  try {
    if (!fs.open(contents, cv::FileStorage::READ | cv::FileStorage::MEMORY)) {
      return OpenCvReadError(path, "not a FileStorage text");
    }
  } catch (const std::exception& e) {  // cv::Exception, or e.g. std::length_error from FileStorage::open
    return OpenCvReadError(path, contents.empty() ? "the file is empty" : e.what());
  }
  const cv::FileNode root = fs.root();
  const OpenCvLines lines(contents, root.isMap() ? root.keys() : std::vector<std::string>{});
  const auto at = [&](const std::string& key) { return path + ":" + std::to_string(lines.Key(key)); };
  if (!root.isMap()) {
    return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(lines.Document()) +
                                                       ": the top level must be a map of keys");
  }
  for (const std::string& key : root.keys()) {
    if (std::find(kOpenCvKeys.begin(), kOpenCvKeys.end(), key) == kOpenCvKeys.end()) {
      problems.Add("unknown key `" + TerminalSafe(key) + "` at " + at(key) +
                   Suggestion(key, {kOpenCvKeys.begin(), kOpenCvKeys.begin() + 4}));
    }
  }
  CameraIntrinsics camera;
  bool ok = ReadOpenCvInt(root["image_width"], "image_width", at("image_width"), &problems, &camera.width_px);
  ok &= ReadOpenCvInt(root["image_height"], "image_height", at("image_height"), &problems, &camera.height_px);
  cv::Mat k, d;
  if (ReadOpenCvMatrix(root["camera_matrix"], "camera_matrix", at("camera_matrix"), &problems, &k)) {
    ReadCameraMatrix(k, at("camera_matrix"), &problems, &camera);
  }
  if (ReadOpenCvMatrix(root["distortion_coefficients"], "distortion_coefficients", at("distortion_coefficients"),
                       &problems, &d)) {
    ReadDistortion(d, at("distortion_coefficients"), &problems, &camera);
  }
  const cv::FileNode fisheye = root["fisheye_model"];
  if (!fisheye.empty() && !fisheye.isNone() && (!fisheye.isInt() || static_cast<int>(fisheye) != 0)) {
    problems.Add("`fisheye_model` at " + at("fisheye_model") +
                 " is set: OpenCV's fisheye model is not selfcal's and is refused");
  }
  if (ok && problems.empty()) AddValidation(camera, at, &problems);
  if (!problems.empty()) return problems.ToStatus("camera intrinsics");
  return camera;
}

// The child's answer to LoadOpenCv, as text: "E<code>\n<message>" or "O" and the intrinsics in hexadecimal
// floating point (exact).
std::string EncodeCamera(const Result<CameraIntrinsics>& result) {
  if (!result.ok()) return "E" + std::to_string(static_cast<int>(result.status().code())) + "\n" + result.status().message();
  const CameraIntrinsics& c = *result;
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), "O %d %d %a %a %a %a %a %a %a %a %a", c.width_px, c.height_px, c.fx_px, c.mu,
                c.cx_px, c.cy_px, c.k1, c.k2, c.p1, c.p2, c.k3);
  return buffer;
}

Result<CameraIntrinsics> DecodeCamera(const std::string& path, const std::string& bytes) {
  int code = 0, consumed = 0;
  if (bytes.rfind('E', 0) == 0 && std::sscanf(bytes.c_str(), "E%d\n%n", &code, &consumed) == 1 && consumed > 0 &&
      code > 0 && code <= static_cast<int>(ErrorCode::kInternal)) {
    return Status::Error(static_cast<ErrorCode>(code), bytes.substr(static_cast<size_t>(consumed)));
  }
  CameraIntrinsics c;
  if (std::sscanf(bytes.c_str(), "O %d %d %la %la %la %la %la %la %la %la %la", &c.width_px, &c.height_px, &c.fx_px,
                  &c.mu, &c.cx_px, &c.cy_px, &c.k1, &c.k2, &c.p1, &c.p2, &c.k3) == 11) {
    return c;
  }
  return Status::Error(ErrorCode::kInternal, "reading " + path + ": the reader's child process sent an unreadable answer");
}

std::string Seconds(std::chrono::milliseconds limit) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", static_cast<double>(limit.count()) / 1000.0);
  return buffer;
}

// LoadOpenCv in a child process that is killed after `limit`: OpenCV 4.6's YAML reader never returns on
// some malformed texts (the fuzzer found twelve; two have the signs refused above, the others none).
Result<CameraIntrinsics> LoadOpenCvWithin(const std::string& path, const std::string& contents,
                                          std::chrono::milliseconds limit) {
  const ChildOutput out = RunInTimeLimitedChild([&] { return EncodeCamera(LoadOpenCv(path, contents)); }, limit);
  switch (out.end) {
    case ChildEnd::kFinished:
      return DecodeCamera(path, out.bytes);
    case ChildEnd::kTimedOut:
      return Status::Error(ErrorCode::kInvalidInput,
                           "cannot read " + path + " as an OpenCV FileStorage file: " + path + ":1: OpenCV's reader " +
                               "did not finish the text within " + Seconds(limit) +
                               " s and was stopped (it loops forever on some malformed YAML); check the " +
                               "file's syntax, or write it again with cv::FileStorage");
    case ChildEnd::kFailed:
      break;
  }
  return Status::Error(ErrorCode::kInternal, "reading " + path + ": OpenCV's reader failed in its child process (" +
                                                 out.detail + ")");
}

// --- ViSP XML -------------------------------------------------------------------------------------------

// Silences std::cout while ViSP's parser talks ("Found camera with name ...").
class QuietCout {
 public:
  QuietCout() : saved_(std::cout.rdbuf(nullptr)) {}
  ~QuietCout() { std::cout.rdbuf(saved_); }

 private:
  std::streambuf* saved_;
};

std::string TempPathFor(const std::string& path) {
  static std::atomic<int> counter{0};
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string stem = std::filesystem::path(path).filename().string();
  return (dir / ("selfcal-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + stem)).string();
}

}  // namespace

Result<CameraIntrinsics> ParseOpenCvCameraText(const std::string& path, const std::string& contents) {
  return LoadOpenCv(path, contents);
}

Result<CameraIntrinsics> LoadCameraFile(const std::string& path, const std::string& camera_name,
                                        std::chrono::milliseconds opencv_limit) {
  Result<std::string> contents = ReadFileCapped(path, kMaxCameraFileBytes);
  if (!contents.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read camera file " + path + ": " + contents.status().message());
  }
  const bool xml = EndsWith(path, ".xml");
  const bool opencv_xml = xml && contents->find("<opencv_storage") != std::string::npos;
  if (xml && !opencv_xml) return ParseVispCameraXml(path, *contents, camera_name);
  if (!xml && !EndsWith(path, ".yaml") && !EndsWith(path, ".yml") && !EndsWith(path, ".json")) {
    return Status::Error(ErrorCode::kInvalidInput, "camera file " + path +
                                                      ": unknown format (expected .yaml, .yml or .json for OpenCV "
                                                      "FileStorage, .xml for ViSP or OpenCV)");
  }
  if (!camera_name.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "camera file " + path + " is an OpenCV file: it holds one camera, "
                                                   "a camera name (`" + camera_name + "`) is for ViSP files");
  }
  return LoadOpenCvWithin(path, *contents, opencv_limit);
}

Status SaveCameraOpenCv(const CameraIntrinsics& camera, const std::string& path) {
  if (const std::string invalid = camera.Validate(); !invalid.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "refusing to write invalid intrinsics to " + path + ":\n" + invalid);
  }
  std::string text;
  try {
    cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs.writeComment(" written by selfcal (docs/camera-files.md); pixels: the centre of the top-left pixel is (0, 0)");
    fs << "image_width" << camera.width_px << "image_height" << camera.height_px;
    const cv::Mat k = (cv::Mat_<double>(3, 3) << camera.fx_px, 0, camera.cx_px, 0, camera.fy_px(), camera.cy_px, 0, 0, 1);
    const cv::Mat d = (cv::Mat_<double>(5, 1) << camera.k1, camera.k2, camera.p1, camera.p2, camera.k3);
    fs << "camera_matrix" << k << "distortion_coefficients" << d;
    text = fs.releaseAndGetString();
  } catch (const std::exception& e) {
    return Status::Error(ErrorCode::kInternal, "cannot format " + path + ": " + std::string(e.what()));
  }
  return WriteFileAtomically(path, text);
}

double FitVispKdu(const CameraIntrinsics& camera) {
  if (camera.k1 == 0) return 0.0;
  double num = 0, den = 0;
  constexpr int kSteps = 40;
  for (int i = 0; i <= kSteps; ++i) {
    for (int j = 0; j <= kSteps; ++j) {
      const Eigen::Vector2d uv(-0.5 + camera.width_px * i / double(kSteps), -0.5 + camera.height_px * j / double(kSteps));
      const Eigen::Vector2d xd = CenteredPixel(camera, uv) / camera.fx_px;
      const Eigen::Vector2d x = PixelToNormalized(camera, camera.fx_px, uv);
      const Eigen::Vector2d basis = xd * xd.squaredNorm();  // x = xd + kdu * basis
      num += basis.dot(x - xd);
      den += basis.squaredNorm();
    }
  }
  return den > 0 ? num / den : 0.0;
}

std::string VispCameraProblems(const CameraIntrinsics& camera) {
  std::string problems = camera.Validate();
  if (camera.k2 != 0 || camera.p1 != 0 || camera.p2 != 0 || camera.k3 != 0) {
    problems += "k2 = " + Num(camera.k2) + ", p1 = " + Num(camera.p1) + ", p2 = " + Num(camera.p2) + ", k3 = " +
                Num(camera.k3) + ": ViSP's perspective model has one radial term (kud = k1) and no tangential "
                "terms; write these intrinsics as an OpenCV file instead\n";
  }
  return problems;
}

Status SaveCameraVisp(const CameraIntrinsics& camera, const std::string& path, const std::string& camera_name) {
  std::string problems = VispCameraProblems(camera);
  if (camera_name.empty()) problems += "the camera name is empty\n";
  if (!problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "refusing to write " + path + " as a ViSP camera file:\n" + problems);
  }
  vpCameraParameters cam;
  if (camera.k1 != 0) {
    cam.initPersProjWithDistortion(camera.fx_px, camera.fy_px(), camera.cx_px, camera.cy_px, camera.k1,
                                   FitVispKdu(camera));
  } else {
    cam.initPersProjWithoutDistortion(camera.fx_px, camera.fy_px(), camera.cx_px, camera.cy_px);
  }
  // vpXmlParserCamera::save adds to an existing file; it writes a fresh temporary one, published atomically.
  const std::string temp = TempPathFor(path);
  int code = vpXmlParserCamera::SEQUENCE_ERROR;
  try {
    QuietCout quiet;
    vpXmlParserCamera parser;
    code = parser.save(cam, temp, camera_name, static_cast<unsigned>(camera.width_px),
                       static_cast<unsigned>(camera.height_px));
  } catch (const std::exception& e) {
    code = vpXmlParserCamera::SEQUENCE_ERROR;
  }
  Result<std::string> text = ReadFileCapped(temp, kMaxCameraFileBytes);
  std::error_code ignored;
  std::filesystem::remove(temp, ignored);
  if (code != vpXmlParserCamera::SEQUENCE_OK || !text.ok()) {
    return Status::Error(ErrorCode::kInternal, "vpXmlParserCamera could not format " + path);
  }
  return WriteFileAtomically(path, *text);
}

}  // namespace selfcal::io
