// The live camera of `run` and `name-dots` from the command line: `--camera v4l2|aravis[:ID]` and the mode
// options shared by both backends (size, frame rate, V4L2 pixel format, exposure, gain), checked where CLI11
// reads them, and the capture::FrameSource they make (docs/real-hardware-quickstart.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/status.h"
#include "capture/frame_source.h"

namespace selfcal::app {

struct CameraMode {
  std::string aravis_id;            // --camera aravis:ID (empty: the first camera Aravis finds)
  int width_px = 0, height_px = 0;  // 0: V4L2 640x480, Aravis the camera's region
  double fps = 0;                   // 0: V4L2 30, Aravis the camera's rate
  std::string format = "YUYV";      // V4L2 pixel format (fourcc)
  double exposure_ms = -1;          // < 0: the camera's current value, locked
  double gain_db = -1;              // Aravis only; < 0: the camera's current value, locked

  bool IsDefault() const;
};

// --camera (one of `backends`, where "aravis" also takes aravis:ID: *backend becomes "aravis" and the ID goes
// to mode->aravis_id) and the mode options.
CLI::Option* AddCameraOptions(CLI::App* cmd, std::string* backend, CameraMode* mode,
                              const std::vector<std::string>& backends);

// The mode as run.json records it (only when not the default, so that earlier sessions' run.json is
// unchanged).
nlohmann::json CameraModeJson(const CameraMode& mode);

// The camera: "v4l2" on `device`, "aravis" by the mode's id. Refuses options the backend does not take.
Result<std::unique_ptr<capture::FrameSource>> MakeLiveCamera(const std::string& backend, const std::string& device,
                                                             const CameraMode& mode);

}  // namespace selfcal::app
