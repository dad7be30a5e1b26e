#include "io/image_files.h"

#include <filesystem>
#include <system_error>

#include <visp3/core/vpException.h>
#include <visp3/io/vpImageIo.h>

namespace selfcal::io {

namespace {

std::string SizeText(unsigned int width, unsigned int height) {
  return std::to_string(width) + "x" + std::to_string(height) + " px";
}

Status ReadOne(const std::string& path, std::size_t max_bytes, std::size_t max_pixels, vpImage<unsigned char>* image) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": not a readable image file (missing, or not a file)");
  }
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec || bytes > max_bytes) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": " +
                                                       (ec ? "cannot read its size: " + ec.message()
                                                           : std::to_string(bytes) + " bytes, more than the limit of " +
                                                                 std::to_string(max_bytes) + " bytes"));
  }
  try {
    vpImageIo::read(*image, path);
  } catch (const vpException& e) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": cannot read the image: " + e.getStringMessage());
  } catch (const std::exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": cannot read the image: " + e.what());
  }
  if (image->getSize() == 0) return Status::Error(ErrorCode::kInvalidInput, path + ": cannot decode the image (empty)");
  if (image->getSize() > max_pixels) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": " + SizeText(image->getWidth(), image->getHeight()) +
                                                       " is more than " + std::to_string(max_pixels) + " pixels");
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<NamedImage>> ReadGreyImages(const std::vector<std::string>& paths, std::size_t max_bytes,
                                               std::size_t max_pixels) {
  std::vector<NamedImage> images;
  images.reserve(paths.size());
  for (const std::string& path : paths) {
    NamedImage named;
    named.path = path;
    if (Status s = ReadOne(path, max_bytes, max_pixels, &named.image); !s.ok()) return s;
    if (!images.empty() && (named.image.getWidth() != images[0].image.getWidth() ||
                            named.image.getHeight() != images[0].image.getHeight())) {
      return Status::Error(ErrorCode::kInvalidInput,
                           path + ": is " + SizeText(named.image.getWidth(), named.image.getHeight()) + ", but " +
                               images[0].path + " is " + SizeText(images[0].image.getWidth(), images[0].image.getHeight()) +
                               " (every image of a set must come from one camera at one resolution)");
    }
    images.push_back(std::move(named));
  }
  return images;
}

}  // namespace selfcal::io
