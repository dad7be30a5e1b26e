// Fuzz harness: an OpenCV FileStorage camera file (docs/camera-files.md) through io::LoadCameraFile, as
// `.yaml` (cv::FileStorage's YAML parser, then selfcal's checks). Refusals should name camera.yaml:<line>:
// cv::FileStorage keeps no lines, io/opencv_lines.h finds the key's in the text (a parse error's line is
// the one cv::FileStorage's parser names).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/camera_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = selfcal::fuzz::WriteFuzzFile("camera.yaml", selfcal::fuzz::AsText(data, size));
  selfcal::Result<selfcal::CameraIntrinsics> camera = selfcal::io::LoadCameraFile(path);
  if (!camera.ok()) selfcal::fuzz::NoteRefusal("camera_opencv", camera.status().message(), path + ":");
  return 0;
}
