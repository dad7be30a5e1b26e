// 8-bit grey PNG encoding and decoding in memory (OpenCV's codecs), shared by recorded sequences and
// session directories, which write frames with base/atomic_file.h and read them back with a size cap.
#pragma once

#include <string>

#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::capture {

// The PNG bytes of `image` at zlib `compression` 0..9. ErrorCode::kInvalidInput on an empty image or an
// encoder failure.
Result<std::string> EncodeGreyPng(const vpImage<unsigned char>& image, int compression);

// Decodes `bytes` (named `what` in messages) that must be an 8-bit single-channel image. ErrorCode::kInvalidInput
// with "cannot decode <what>: ..." otherwise. The caller checks sizes and caps the input.
Result<vpImage<unsigned char>> DecodeGreyPng(const std::string& bytes, const std::string& what);

}  // namespace selfcal::capture
