// Internal to io: the strict reader of ViSP's camera XML (io/camera_file.h). A small XML subset (elements,
// text, comments, the <?xml?> declaration; no attributes, DTDs or CDATA) with the line of every element, so
// that unknown, missing and repeated elements are named with FILE:LINE.
#pragma once

#include <string>

#include "base/status.h"
#include "camera/camera.h"

namespace selfcal::io {

// The camera `camera_name` (empty: the only one) of the vpXmlParserCamera document `contents` read from
// `path`: its perspectiveProjWithDistortion model if it has one, else perspectiveProjWithoutDistortion.
Result<CameraIntrinsics> ParseVispCameraXml(const std::string& path, const std::string& contents,
                                            const std::string& camera_name);

}  // namespace selfcal::io
