#include "capture/mjpeg_decode.h"

#include <csetjmp>
#include <cstdio>
#include <string>

#include <jpeglib.h>

#include "capture/frame_source.h"

namespace selfcal::capture {

namespace {

// libjpeg's error manager, turned into a longjmp back to DecodeMjpegFrame with the message kept. Warnings
// (corrupt or missing data that libjpeg would paper over) count as errors.
struct ErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void OnError(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void OnMessage(j_common_ptr cinfo, int msg_level) {
  if (msg_level < 0) OnError(cinfo);  // a warning: corrupt data
}

}  // namespace

Result<vpImage<unsigned char>> DecodeMjpegFrame(const uint8_t* data, size_t size, const std::string& source,
                                                int expected_width_px, int expected_height_px) {
  const std::string who = source + ": MJPEG frame of " + std::to_string(size) + " bytes ";
  if (data == nullptr || size < 4 || data[0] != 0xFF || data[1] != 0xD8) {
    return CaptureFailure(CaptureError::kBadFrame, who + "does not start with a JPEG start-of-image marker");
  }
  vpImage<unsigned char> image;
  jpeg_decompress_struct cinfo{};
  ErrorManager err{};
  cinfo.err = jpeg_std_error(&err.base);
  err.base.error_exit = OnError;
  err.base.emit_message = OnMessage;
  // Everything the longjmp may skip is plain data or destroyed below; `image` is resized only after the
  // header was read and holds no state libjpeg refers to.
  if (setjmp(err.jump) != 0) {
    jpeg_destroy_decompress(&cinfo);
    return CaptureFailure(CaptureError::kBadFrame,
                          who + "is corrupt or truncated (libjpeg: " + std::string(err.message) + ")");
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  const int width = static_cast<int>(cinfo.image_width), height = static_cast<int>(cinfo.image_height);
  if ((expected_width_px > 0 && width != expected_width_px) || (expected_height_px > 0 && height != expected_height_px)) {
    jpeg_destroy_decompress(&cinfo);
    return CaptureFailure(CaptureError::kFormatMismatch,
                          who + "is " + std::to_string(width) + "x" + std::to_string(height) + ", not the " +
                              std::to_string(expected_width_px) + "x" + std::to_string(expected_height_px) +
                              " negotiated with the camera");
  }
  cinfo.out_color_space = JCS_GRAYSCALE;  // the luminance plane alone: no colour conversion
  jpeg_start_decompress(&cinfo);
  image.resize(static_cast<unsigned>(height), static_cast<unsigned>(width));
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = image[cinfo.output_scanline];
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return image;
}

}  // namespace selfcal::capture
