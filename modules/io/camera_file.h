// Camera intrinsics files of other tools (docs/camera-files.md):
//
// - OpenCV FileStorage (`.yaml`, `.yml`, `.json`, or `.xml` whose root is <opencv_storage>), the form
//   cv::calibrateCamera's samples write: image_width, image_height, camera_matrix (3x3),
//   distortion_coefficients (k1, k2, p1, p2[, k3[, ...]]); read and written with cv::FileStorage itself.
// - ViSP's vpXmlParserCamera XML (`.xml`): <root><camera><name>, image_width, image_height and a <model>
//   of type perspectiveProjWithoutDistortion (px, py, u0, v0) or perspectiveProjWithDistortion (also
//   kud, kdu); written with vpXmlParserCamera itself.
//
// Pixels: OpenCV's (c_x, c_y) and ViSP's (u0, v0) use selfcal's convention (the centre of the top-left
// pixel is (0, 0)), so they are copied unchanged; f_y = mu f_x. ViSP's projection u = u0 + px x (1 + kud
// r^2) is OpenCV's with k1 = kud; its kdu is ViSP's own approximate pixel-to-metre inverse, which selfcal
// does not use (it inverts the projection exactly), and writes as the least-squares fit over the image.
// What selfcal cannot represent is refused, never approximated: skew, OpenCV's rational, thin-prism and
// tilt terms, OpenCV's fisheye model, ViSP's Kannala-Brandt model, and (writing ViSP) any of k2, p1, p2,
// k3. Every error is ErrorCode::kInvalidInput and names the file (and the key); nothing is written on error.
#pragma once

#include <chrono>
#include <string>

#include "base/status.h"
#include "camera/camera.h"

namespace selfcal::io {

// How long OpenCV may take to read a camera file (at most 16 MiB; a real one takes milliseconds).
inline constexpr std::chrono::milliseconds kOpenCvReadLimit{10000};

// Reads the intrinsics of `path` (format from the name and, for `.xml`, the root element). `camera_name`
// selects a camera of a ViSP file (empty: the file must hold exactly one); not allowed for OpenCV files.
// OpenCV files are read in a child process stopped after `opencv_limit` (OpenCV 4.6's YAML reader loops
// forever on some malformed texts): a text it does not finish is refused, naming the file.
Result<CameraIntrinsics> LoadCameraFile(const std::string& path, const std::string& camera_name = "",
                                        std::chrono::milliseconds opencv_limit = kOpenCvReadLimit);

// The OpenCV reading of LoadCameraFile on the text `contents` of `path`, in this process and without a
// time limit: for the fuzz harness, whose coverage a child process would hide.
Result<CameraIntrinsics> ParseOpenCvCameraText(const std::string& path, const std::string& contents);

// OK when this program can read and write OpenCV and ViSP camera files: always where the backend is
// linked; where it is loaded when first needed (io/camera_formats.h, `selfcal`), once it has loaded. For
// callers that refuse before they compute or write anything.
Status CheckCameraFileSupport();
// Writes cv::FileStorage YAML (image_width, image_height, camera_matrix, distortion_coefficients with
// all five coefficients), atomically.
Status SaveCameraOpenCv(const CameraIntrinsics& camera, const std::string& path);

// Why `camera` cannot be written as a ViSP camera file, one problem per line (invalid intrinsics; k2, p1,
// p2 or k3 non-zero: ViSP's perspective model has one radial term), or empty when it can: for callers that
// refuse before writing anything.
std::string VispCameraProblems(const CameraIntrinsics& camera);

// Writes vpXmlParserCamera XML with one camera `camera_name`, atomically: perspectiveProjWithDistortion
// when k1 != 0, else perspectiveProjWithoutDistortion. Refuses a camera with k2, p1, p2 or k3.
Status SaveCameraVisp(const CameraIntrinsics& camera, const std::string& path, const std::string& camera_name = "Camera");

// kdu of ViSP's inverse x = x_d (1 + kdu r_d^2) fitted (least squares, normalised coordinates on a grid
// over the image) to the exact inverse of the radial model with k1 = kud.
double FitVispKdu(const CameraIntrinsics& camera);

}  // namespace selfcal::io
