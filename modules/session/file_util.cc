#include "session/file_util.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "base/atomic_file.h"

namespace selfcal::session::internal {

ErrorCode ErrorCodeForErrno(int error) {
  return error == ENOSPC || error == EDQUOT || error == EIO ? ErrorCode::kHardware : ErrorCode::kInvalidInput;
}

Status SystemError(const std::string& what, const std::string& path, int error) {
  return Status::Error(ErrorCodeForErrno(error), what + " " + path + ": " + std::strerror(error))
      .WithDetail(kErrnoDomain, error);
}

Status WithErrnoErrorCode(const Status& status) {
  if (status.ok() || std::strcmp(status.detail_domain(), kErrnoDomain) != 0) return status;
  return Status::Error(ErrorCodeForErrno(status.detail()), status.message()).WithDetail(kErrnoDomain, status.detail());
}

bool SafeFileName(const std::string& name) {
  if (name.empty() || name.size() > 255 || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return c > 0x20 && c < 0x7F && c != '/' && c != '\\'; });
}

std::string Join(const std::string& directory, const std::string& name) {
  if (directory.empty()) return name;
  return directory.back() == '/' ? directory + name : directory + "/" + name;
}

}  // namespace selfcal::session::internal
