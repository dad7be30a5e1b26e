// CameraFormats() of programs that load the backend when they first need it (io/camera_formats.h):
// libselfcal_camera_formats.so from the executable's own directory, opened once with dlopen.
#include <dlfcn.h>

#include <filesystem>

#include "io/camera_formats.h"

namespace selfcal::io::internal {

namespace {

constexpr const char* kLibraryName = "libselfcal_camera_formats.so";

Result<const CameraFormatBackend*> Load() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::string path = (error ? std::filesystem::path(kLibraryName) : self.parent_path() / kLibraryName).string();
  const auto failure = [&](const std::string& why) {
    return Status::Error(ErrorCode::kInternal,
                         "OpenCV and ViSP camera files are read and written by " + path + ", which " + why +
                             "; it is built beside selfcal and must be installed beside it");
  };
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* what = ::dlerror();
    return failure(std::string("could not be loaded (") + (what != nullptr ? what : "unknown reason") + ")");
  }
  using Entry = const CameraFormatBackend* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "selfcal_camera_format_backend"));
  const CameraFormatBackend* backend = entry != nullptr ? entry() : nullptr;
  if (backend == nullptr || backend->version != kCameraFormatBackendVersion) {
    return failure("is not the one this selfcal was built with");
  }
  return backend;  // the handle stays open for the life of the process
}

}  // namespace

Result<const CameraFormatBackend*> CameraFormats() {
  static const Result<const CameraFormatBackend*> loaded = Load();  // once, thread-safe
  return loaded;
}

}  // namespace selfcal::io::internal
