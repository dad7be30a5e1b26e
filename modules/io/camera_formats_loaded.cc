// CameraFormats() of programs that load the backend when they first need it (io/camera_formats.h):
// libselfcal_camera_formats.so from the program's private library directory, opened once with dlopen.
#include <dlfcn.h>

#include <filesystem>
#include <string>
#include <vector>

#include "base/install_layout.h"
#include "io/camera_formats.h"

namespace selfcal::io::internal {

namespace {

constexpr const char* kLibraryName = "libselfcal_camera_formats.so";

// The library in the first of the program's private library directories that has it (base/install_layout.h:
// <prefix>/lib/selfcal installed, beside the program in a build tree); "" when none has it, `searched` then
// lists the places looked in.
std::string FindLibrary(std::string* searched) {
  std::error_code error;
  for (const std::string& dir : ProgramLayout().library_dirs) {
    const std::filesystem::path candidate = std::filesystem::path(dir) / kLibraryName;
    if (std::filesystem::exists(candidate, error)) return candidate.string();
    *searched += (searched->empty() ? "" : ", ") + candidate.string();
  }
  return std::string();
}

Result<const CameraFormatBackend*> Load() {
  std::string searched;
  const std::string path = FindLibrary(&searched);
  const auto failure = [&](const std::string& what) {
    return Status::Error(ErrorCode::kInternal,
                         "OpenCV and ViSP camera files are read and written by " + what +
                             "; it is installed with selfcal (lib/selfcal under its prefix; beside selfcal in a "
                             "build tree)");
  };
  if (path.empty()) {
    return failure(std::string(kLibraryName) + ", which was not found (searched " +
                   (searched.empty() ? std::string("nothing: the program's own path is unknown") : searched) + ")");
  }
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* what = ::dlerror();
    return failure(path + ", which could not be loaded (" + (what != nullptr ? what : "unknown reason") + ")");
  }
  using Entry = const CameraFormatBackend* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "selfcal_camera_format_backend"));
  const CameraFormatBackend* backend = entry != nullptr ? entry() : nullptr;
  if (backend == nullptr || backend->version != kCameraFormatBackendVersion) {
    return failure(path + ", which is not the one this selfcal was built with");
  }
  return backend;  // the handle stays open for the life of the process
}

}  // namespace

Result<const CameraFormatBackend*> CameraFormats() {
  static const Result<const CameraFormatBackend*> loaded = Load();  // once, thread-safe
  return loaded;
}

}  // namespace selfcal::io::internal
