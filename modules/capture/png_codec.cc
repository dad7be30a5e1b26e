#include "capture/png_codec.h"

#include <cstring>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace selfcal::capture {

Result<std::string> EncodeGreyPng(const vpImage<unsigned char>& image, int compression) {
  if (image.getWidth() == 0 || image.getHeight() == 0) {
    return Status::Error(ErrorCode::kInvalidInput, "PNG encoding: empty image");
  }
  // The image's pixels without a copy (vpImage is row-major, contiguous).
  const cv::Mat view(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1,
                     const_cast<unsigned char*>(image.bitmap));
  std::vector<unsigned char> png;
  try {
    if (!cv::imencode(".png", view, png, {cv::IMWRITE_PNG_COMPRESSION, compression})) {
      return Status::Error(ErrorCode::kInvalidInput, "PNG encoding failed");
    }
  } catch (const cv::Exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, std::string("PNG encoding failed: ") + e.what());
  }
  return std::string(png.begin(), png.end());
}

Result<vpImage<unsigned char>> DecodeGreyPng(const std::string& bytes, const std::string& what) {
  cv::Mat decoded;
  try {
    const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data()));
    decoded = cv::imdecode(raw, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& ex) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot decode " + what + ": " + ex.what());
  }
  if (decoded.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot decode " + what + ": truncated or corrupted PNG data");
  }
  if (decoded.type() != CV_8UC1) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot decode " + what + ": " + std::to_string(decoded.channels()) +
                                               " channel(s) or not 8 bit; expected 8-bit grey");
  }
  vpImage<unsigned char> image(static_cast<unsigned>(decoded.rows), static_cast<unsigned>(decoded.cols));
  for (int v = 0; v < decoded.rows; ++v) {
    std::memcpy(image[v], decoded.ptr<unsigned char>(v), static_cast<size_t>(decoded.cols));
  }
  return image;
}

}  // namespace selfcal::capture
