// CameraFormats() of programs that link the backend (io/camera_formats.h): it is compiled in.
#include "io/camera_formats.h"

namespace selfcal::io::internal {

Result<const CameraFormatBackend*> CameraFormats() { return selfcal_camera_format_backend(); }

}  // namespace selfcal::io::internal
