// MJPEG frames (what most USB cameras send at 1280x720 and above) decoded to 8-bit grey with libjpeg-turbo
// (Debian's libjpeg62-turbo, through its libjpeg API: the decoder OpenCV and ViSP use underneath, called
// directly so that a damaged frame is refused instead of patched). Kept apart from the device so that it is
// tested on recorded frames (test/data/mjpeg).
//
// A frame is refused (kBadFrame, naming `source`) when it is not a JPEG, when libjpeg reports an error, or
// when it reports any warning: a truncated frame (a USB packet lost) is a warning to libjpeg, which fills
// the missing rows with grey and carries on, and such a frame must never be measured. Frames without
// Huffman tables (the usual UVC MJPEG) are decoded with the standard tables libjpeg-turbo supplies.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::capture {

// The frame's luminance. expected_width_px / expected_height_px > 0: a frame of another size is refused
// (kFormatMismatch), as the V4L2 camera negotiated that size.
Result<vpImage<unsigned char>> DecodeMjpegFrame(const uint8_t* data, size_t size, const std::string& source,
                                                int expected_width_px = 0, int expected_height_px = 0);

}  // namespace selfcal::capture
