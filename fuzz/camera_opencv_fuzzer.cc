// Fuzz harness: an OpenCV FileStorage camera file (docs/camera-files.md) through io::LoadCameraFile, as
// `.yaml` (cv::FileStorage's YAML parser, then selfcal's checks). Refusals should name camera.yaml:<line>:
// cv::FileStorage keeps no lines, io/opencv_lines.h finds the key's in the text (a parse error's line is
// the one cv::FileStorage's parser names).
//
// LoadCameraFile reads OpenCV files in a child process with a time limit (OpenCV 4.6's YAML reader loops
// forever on some texts): here the limit is 2 s. The child's coverage is invisible to the fuzzer, so each
// text the child finishes is read again in this process (ParseOpenCvCameraText), which must give the same
// answer; a text the child did not finish is not read here, and its refusal is counted.
//
// A fork per input costs an ASan process 20 ms or more, so the long campaign runs with
// SELFCAL_FUZZ_OPENCV_IN_PROCESS=1 (`scripts/fuzz --opencv-in-process`): the text is read in this
// process only, OpenCV's endless loops show as libFuzzer timeouts, and the regression driver (which runs
// the child path) then shows each of them refused by the time limit.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/camera_file.h"

namespace {

bool Same(const selfcal::Result<selfcal::CameraIntrinsics>& a, const selfcal::Result<selfcal::CameraIntrinsics>& b) {
  if (a.ok() != b.ok()) return false;
  if (!a.ok()) return a.status().code() == b.status().code() && a.status().message() == b.status().message();
  return a->width_px == b->width_px && a->height_px == b->height_px &&
         selfcal::IntrinsicsOf(*a) == selfcal::IntrinsicsOf(*b);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = selfcal::fuzz::AsText(data, size);
  const std::string path = selfcal::fuzz::WriteFuzzFile("camera.yaml", text);
  static const bool in_process = std::getenv("SELFCAL_FUZZ_OPENCV_IN_PROCESS") != nullptr;
  if (in_process) {
    const selfcal::Result<selfcal::CameraIntrinsics> camera = selfcal::io::ParseOpenCvCameraText(path, text);
    if (!camera.ok()) selfcal::fuzz::NoteRefusal("camera_opencv", camera.status().message(), path + ":");
    return 0;
  }
  const selfcal::Result<selfcal::CameraIntrinsics> camera =
      selfcal::io::LoadCameraFile(path, "", std::chrono::milliseconds(2000));
  if (!camera.ok()) selfcal::fuzz::NoteRefusal("camera_opencv", camera.status().message(), path + ":");
  const bool stopped = !camera.ok() && camera.status().message().find("was stopped") != std::string::npos;
  if (!stopped && !Same(camera, selfcal::io::ParseOpenCvCameraText(path, text))) {
    std::fprintf(stderr, "the child process and this process read %s differently\n", path.c_str());
    std::abort();
  }
  return 0;
}
