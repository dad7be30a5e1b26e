#include "io/camera_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <vector>

#include "base/atomic_file.h"
#include "base/terminal_text.h"
#include "base/time_limited_child.h"
#include "base/xml_scan.h"
#include "io/camera_formats.h"
#include "io/camera_xml.h"
#include "io/opencv_lines.h"
#include "io/yaml_schema.h"
#include "yaml/yaml_reader.h"

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

bool ReadOpenCvInt(const internal::FileStorageScalar& node, const std::string& key, const std::string& file,
                   Problems* problems, int* out) {
  if (!node.present) {
    problems->Add("missing key `" + key + "` in the document at " + file);
    return false;
  }
  if (!node.is_int || node.value < 1 || node.value > 100000) {
    problems->Add("`" + key + "` at " + file + " must be an integer in [1, 100000]");
    return false;
  }
  *out = node.value;
  return true;
}

// A matrix's entries as cv::FileStorage read them (io/camera_formats.h), row by row.
struct Matrix {
  int rows = 0, cols = 0;
  std::vector<double> data;
  double at(int r, int c) const { return data[static_cast<size_t>(r * cols + c)]; }
};

bool ReadOpenCvMatrix(const internal::FileStorageMatrix& node, const std::string& key, const std::string& file,
                      Problems* problems, Matrix* out) {
  if (!node.present) {
    problems->Add("missing key `" + key + "` in the document at " + file);
    return false;
  }
  if (!node.header_ok) {
    problems->Add("`" + key + "` at " + file + " must be an opencv-matrix (rows, cols, dt, data) of at most 16 " +
                  "entries, with rows x cols values in data");
    return false;
  }
  if (!node.read_ok) {
    problems->Add("`" + key + "` at " + file + " must be an opencv-matrix (rows, cols, dt, data)");
    return false;
  }
  for (double v : node.data) {
    if (!std::isfinite(v)) {
      problems->Add("`" + key + "` at " + file + " has a non-finite entry");
      return false;
    }
  }
  *out = Matrix{node.rows, node.cols, node.data};
  return true;
}

// K = [fx 0 cx; 0 fy cy; 0 0 1] exactly (no skew: selfcal's model has none).
void ReadCameraMatrix(const Matrix& k, const std::string& file, Problems* problems, CameraIntrinsics* camera) {
  if (k.rows != 3 || k.cols != 3) {
    problems->Add("`camera_matrix` at " + file + " is " + std::to_string(k.rows) + "x" + std::to_string(k.cols) +
                  ", must be 3x3");
    return;
  }
  if (k.at(0, 1) != 0) {
    problems->Add("`camera_matrix` at " + file + " has skew " + Num(k.at(0, 1)) +
                  " (entry [0][1]); selfcal's camera model has none and cannot represent it");
  }
  if (k.at(1, 0) != 0 || k.at(2, 0) != 0 || k.at(2, 1) != 0 || k.at(2, 2) != 1) {
    problems->Add("`camera_matrix` at " + file + " must be [fx 0 cx; 0 fy cy; 0 0 1]");
  }
  camera->fx_px = k.at(0, 0);
  camera->cx_px = k.at(0, 2);
  camera->cy_px = k.at(1, 2);
  if (!(camera->fx_px > 0) || !(k.at(1, 1) > 0)) {
    problems->Add("`camera_matrix` at " + file + ": fx and fy must be > 0");
    return;
  }
  camera->mu = k.at(1, 1) / camera->fx_px;
}

// OpenCV's order k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx, ty]]]]: the terms after k3 must be zero.
void ReadDistortion(const Matrix& d, const std::string& file, Problems* problems, CameraIntrinsics* camera) {
  const int n = static_cast<int>(d.data.size());
  if ((d.rows != 1 && d.cols != 1) || (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
    problems->Add("`distortion_coefficients` at " + file + " is " + std::to_string(d.rows) + "x" +
                  std::to_string(d.cols) + ", must be a vector of 4, 5, 8, 12 or 14 coefficients");
    return;
  }
  const double* v = d.data.data();
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

// Before OpenCV's reader, which recurses once per nesting level (100,000 levels crash it) and keeps the
// last of a repeated key: the text's nesting and keys are checked here, by line. An XML text (its first
// non-blank character `<`) by the non-recursive scan of base/xml_scan.h (depth, repeated sibling elements
// except OpenCV's sequence items `<_>`, UTF-8); a YAML or JSON text by selfcal's strict YAML reader (depth,
// duplicate keys, UTF-8; OpenCV's `!!opencv-matrix` tags accepted).
Status CheckOpenCvStructure(const std::string& path, const std::string& contents) {
  const size_t first = contents.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && contents[first] == '<') {
    XmlScanLimits limits;
    limits.kind = "an OpenCV camera file";
    limits.max_bytes = kMaxCameraFileBytes;
    limits.require_utf8 = true;
    limits.refuse_repeated_siblings = true;
    limits.repeatable = {"_"};
    return ScanXml(contents, path, limits);
  }
  yaml::YamlRules rules;
  rules.max_bytes = kMaxCameraFileBytes;
  rules.accepted_tag_prefix = "tag:yaml.org,2002:opencv-";
  const Result<yaml::YamlDocument> doc = yaml::ParseYamlText(contents, path, rules);
  return doc.ok() ? Status::Ok() : doc.status();
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
  if (Status s = CheckOpenCvStructure(path, contents); !s.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as an OpenCV FileStorage file: " + s.message());
  }
  const Result<const internal::CameraFormatBackend*> backend = internal::CameraFormats();
  if (!backend.ok()) return backend.status();
  const internal::FileStorageCamera fs = (*backend)->read_opencv(contents);
  if (fs.open == internal::FileStorageCamera::Open::kRefused) return OpenCvReadError(path, "not a FileStorage text");
  if (fs.open == internal::FileStorageCamera::Open::kThrew) {
    return OpenCvReadError(path, contents.empty() ? "the file is empty" : fs.what);
  }
  const OpenCvLines lines(contents, fs.keys);
  const auto at = [&](const std::string& key) { return path + ":" + std::to_string(lines.Key(key)); };
  if (!fs.root_is_map) {
    return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(lines.Document()) +
                                                       ": the top level must be a map of keys");
  }
  for (const std::string& key : fs.keys) {
    if (std::find(kOpenCvKeys.begin(), kOpenCvKeys.end(), key) == kOpenCvKeys.end()) {
      problems.Add("unknown key `" + TerminalSafe(key) + "` at " + at(key) +
                   Suggestion(key, {kOpenCvKeys.begin(), kOpenCvKeys.begin() + 4}));
    }
  }
  CameraIntrinsics camera;
  bool ok = ReadOpenCvInt(fs.image_width, "image_width", at("image_width"), &problems, &camera.width_px);
  ok &= ReadOpenCvInt(fs.image_height, "image_height", at("image_height"), &problems, &camera.height_px);
  Matrix k, d;
  if (ReadOpenCvMatrix(fs.camera_matrix, "camera_matrix", at("camera_matrix"), &problems, &k)) {
    ReadCameraMatrix(k, at("camera_matrix"), &problems, &camera);
  }
  if (ReadOpenCvMatrix(fs.distortion_coefficients, "distortion_coefficients", at("distortion_coefficients"),
                       &problems, &d)) {
    ReadDistortion(d, at("distortion_coefficients"), &problems, &camera);
  }
  const internal::FileStorageScalar& fisheye = fs.fisheye_model;
  if (fisheye.present && (!fisheye.is_int || fisheye.value != 0)) {
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
  // Loaded here, not in the child: once for the process, and a missing backend is this process's error.
  if (Status s = CheckCameraFileSupport(); !s.ok()) return s;
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
    case ChildEnd::kCrashed:
      // The text made OpenCV's reader crash: the file's fault as far as the user can act on it.
      return Status::Error(ErrorCode::kInvalidInput,
                           "cannot read " + path + " as an OpenCV FileStorage file: " + path + ":1: OpenCV's reader " +
                               "crashed on the text (" + out.detail + "); check the file's syntax, or write it " +
                               "again with cv::FileStorage");
    case ChildEnd::kFailed:
      break;
  }
  return Status::Error(ErrorCode::kInternal, "reading " + path + ": OpenCV's reader failed in its child process (" +
                                                 out.detail + ")");
}

// --- ViSP XML -------------------------------------------------------------------------------------------

std::string TempPathFor(const std::string& path) {
  static std::atomic<int> counter{0};
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string stem = std::filesystem::path(path).filename().string();
  return (dir / ("selfcal-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + stem)).string();
}

}  // namespace

Status CheckCameraFileSupport() {
  const Result<const internal::CameraFormatBackend*> backend = internal::CameraFormats();
  return backend.ok() ? Status::Ok() : backend.status();
}

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
  const Result<const internal::CameraFormatBackend*> backend = internal::CameraFormats();
  if (!backend.ok()) return backend.status();
  internal::OpenCvCameraValues values;
  values.width_px = camera.width_px;
  values.height_px = camera.height_px;
  const double k[9] = {camera.fx_px, 0, camera.cx_px, 0, camera.fy_px(), camera.cy_px, 0, 0, 1};
  const double d[5] = {camera.k1, camera.k2, camera.p1, camera.p2, camera.k3};
  std::copy(std::begin(k), std::end(k), values.camera_matrix);
  std::copy(std::begin(d), std::end(d), values.distortion_coefficients);
  values.comment = " written by selfcal (docs/camera-files.md); pixels: the centre of the top-left pixel is (0, 0)";
  std::string text, error;
  if (!(*backend)->format_opencv(values, &text, &error)) {
    return Status::Error(ErrorCode::kInternal, "cannot format " + path + ": " + error);
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
  const Result<const internal::CameraFormatBackend*> backend = internal::CameraFormats();
  if (!backend.ok()) return backend.status();
  internal::VispCameraValues values;
  values.name = camera_name;
  values.width_px = static_cast<unsigned>(camera.width_px);
  values.height_px = static_cast<unsigned>(camera.height_px);
  values.px = camera.fx_px;
  values.py = camera.fy_px();
  values.u0 = camera.cx_px;
  values.v0 = camera.cy_px;
  values.with_distortion = camera.k1 != 0;
  if (values.with_distortion) {
    values.kud = camera.k1;
    values.kdu = FitVispKdu(camera);
  }
  // vpXmlParserCamera::save adds to an existing file; it writes a fresh temporary one, published atomically.
  const std::string temp = TempPathFor(path);
  const bool saved = (*backend)->save_visp(values, temp);
  Result<std::string> text = ReadFileCapped(temp, kMaxCameraFileBytes);
  std::error_code ignored;
  std::filesystem::remove(temp, ignored);
  if (!saved || !text.ok()) {
    return Status::Error(ErrorCode::kInternal, "vpXmlParserCamera could not format " + path);
  }
  return WriteFileAtomically(path, *text);
}

}  // namespace selfcal::io
