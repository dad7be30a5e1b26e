#include "app/camera_options.h"

#include <cmath>

#include "capture/aravis_camera.h"
#include "capture/v4l2_camera.h"

namespace selfcal::app {

bool CameraMode::IsDefault() const {
  const CameraMode d;
  return aravis_id == d.aravis_id && width_px == d.width_px && height_px == d.height_px && fps == d.fps &&
         format == d.format && exposure_ms == d.exposure_ms && gain_db == d.gain_db;
}

CLI::Option* AddCameraOptions(CLI::App* cmd, std::string* backend, CameraMode* mode,
                              const std::vector<std::string>& backends) {
  std::string names;
  for (const std::string& b : backends) names += (names.empty() ? "" : ", ") + (b == "aravis" ? b + "[:ID]" : b);
  CLI::Validator choice(
      [mode](std::string& value) -> std::string {
        if (value.rfind("aravis:", 0) == 0) {  // the camera's id: the backend is checked by IsMember below
          mode->aravis_id = value.substr(7);
          value = "aravis";
        }
        return "";
      },
      "", "camera");
  CLI::Option* option = cmd->add_option("--camera", *backend,
                                        "Camera backend: " + names +
                                            " (aravis: a GigE Vision or USB3 Vision camera; ID as arv-tool-0.8 "
                                            "lists it, default the first one found)")
                            ->transform(choice)
                            ->check(CLI::IsMember(backends));
  const char* group = "Camera mode (v4l2, aravis)";
  cmd->add_option("--camera-width-px", mode->width_px, "Image width (v4l2 default 640; aravis: the camera's)")
      ->check(CLI::Range(1, 16384))
      ->default_str("")  // 0, "not given", is below the range: the text says the default
      ->group(group);
  cmd->add_option("--camera-height-px", mode->height_px, "Image height (v4l2 default 480; aravis: the camera's)")
      ->check(CLI::Range(1, 16384))
      ->default_str("")
      ->group(group);
  cmd->add_option("--camera-fps", mode->fps, "Frame rate (v4l2 default 30; aravis: the camera's)")
      ->check(CLI::Range(0.1, 1000.0))
      ->default_str("")
      ->group(group);
  cmd->add_option("--camera-format", mode->format, "v4l2 pixel format: MJPG (decoded), YUYV (default), GREY, RGB3, "
                                                   "BGR3, RGB4; `v4l2-ctl --list-formats-ext` lists the camera's")
      ->check(CLI::IsMember({"MJPG", "YUYV", "GREY", "RGB3", "BGR3", "RGB4"}))
      ->group(group);
  cmd->add_option("--exposure-ms", mode->exposure_ms, "Locked exposure time, ms (default: the camera's current one)")
      ->check(CLI::Range(0.001, 10000.0))
      ->default_str("")  // the sentinel below the range is not a value to show
      ->group(group);
  cmd->add_option("--gain-db", mode->gain_db, "aravis: locked gain, dB (default: the camera's current one)")
      ->check(CLI::Range(0.0, 100.0))
      ->default_str("")
      ->group(group);
  return option;
}

nlohmann::json CameraModeJson(const CameraMode& mode) {
  nlohmann::json j = nlohmann::json::object();
  if (mode.width_px > 0) j["width_px"] = mode.width_px;
  if (mode.height_px > 0) j["height_px"] = mode.height_px;
  if (mode.fps > 0) j["fps"] = mode.fps;
  if (mode.format != CameraMode().format) j["format"] = mode.format;
  if (mode.exposure_ms >= 0) j["exposure_ms"] = mode.exposure_ms;
  if (mode.gain_db >= 0) j["gain_db"] = mode.gain_db;
  return j;
}

Result<std::unique_ptr<capture::FrameSource>> MakeLiveCamera(const std::string& backend, const std::string& device,
                                                             const CameraMode& mode) {
  if ((mode.width_px > 0) != (mode.height_px > 0)) {
    return Status::Error(ErrorCode::kInvalidInput, "--camera-width-px and --camera-height-px go together");
  }
  if (backend == "aravis") {
    if (mode.format != CameraMode().format) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "--camera-format is a V4L2 option; an Aravis camera is read as Mono8 (8-bit grey)");
    }
    capture::AravisOptions options;
    options.camera_id = mode.aravis_id;
    options.fake_interface = mode.aravis_id.rfind("Fake", 0) == 0;  // Aravis' simulated camera, for rehearsals
    options.width_px = mode.width_px;
    options.height_px = mode.height_px;
    options.frame_rate_hz = mode.fps;
    options.exposure_s = mode.exposure_ms < 0 ? -1 : 1e-3 * mode.exposure_ms;
    options.gain_db = mode.gain_db;
    return std::unique_ptr<capture::FrameSource>(std::make_unique<capture::AravisCamera>(options));
  }
  if (backend != "v4l2") return Status::Error(ErrorCode::kInvalidInput, "--camera must be v4l2 or aravis[:ID]");
  if (mode.gain_db >= 0) {
    return Status::Error(ErrorCode::kInvalidInput, "--gain-db is an Aravis option; a V4L2 camera's gain is locked "
                                                   "with auto gain off at its current value");
  }
  capture::V4l2Options options;
  options.device = device;
  if (mode.width_px > 0) {
    options.width_px = mode.width_px;
    options.height_px = mode.height_px;
  }
  if (mode.fps > 0) {
    options.frame_period_s = 1.0 / mode.fps;
    options.exact_frame_period = true;  // a rate the user chose is checked; the default 30 fps only asked for
  }
  capture::V4l2PixelFormatFromName(mode.format, &options.pixel_format);  // checked by --camera-format
  if (mode.exposure_ms >= 0) options.exposure_absolute_100us = static_cast<int>(std::lround(10 * mode.exposure_ms));
  return std::unique_ptr<capture::FrameSource>(std::make_unique<capture::V4l2Camera>(options));
}

}  // namespace selfcal::app
