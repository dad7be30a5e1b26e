#include "base/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace selfcal {

namespace {

Status Failure(const std::string& what, const std::string& path, int error) {
  return Status::Error(ErrorCode::kInvalidInput, "cannot write " + path + ": " + what + ": " + std::strerror(error))
      .WithDetail(kErrnoDomain, error);
}

std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string BaseNameOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

bool WriteAllToFd(int fd, const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) errno = EIO;  // no progress and no error: do not loop forever
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

bool FsyncRetrying(int fd) {
  int rc;
  do {
    rc = ::fsync(fd);
  } while (rc != 0 && errno == EINTR);
  return rc == 0;
}

bool FsyncDirectory(const std::string& directory) {
  const int dir_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return false;
  const bool synced = FsyncRetrying(dir_fd);
  const int error = errno;
  ::close(dir_fd);
  errno = error;
  return synced;
}

Status WriteFileAtomically(const std::string& path, const std::string& contents, Publish publish) {
  const std::string base = BaseNameOf(path);
  if (path.empty() || base.empty() || base == "." || base == "..") {
    return Status::Error(ErrorCode::kInvalidInput, "cannot write `" + path + "`: not a file name");
  }
  const std::string directory = DirectoryOf(path);
  std::string temp_name = directory + "/." + base + ".tmp.XXXXXX";
  std::vector<char> temp(temp_name.begin(), temp_name.end());
  temp.push_back('\0');
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return Failure("cannot create a temporary file in " + directory, path, errno);
  temp_name = temp.data();
  auto abandon = [&](const std::string& what, int error, bool close_fd) {
    if (close_fd) ::close(fd);
    ::unlink(temp_name.c_str());
    return Failure(what, path, error);
  };
  if (!WriteAllToFd(fd, contents)) return abandon("write failed", errno, true);
  if (::fchmod(fd, 0644) != 0) return abandon("chmod failed", errno, true);
  if (!FsyncRetrying(fd)) return abandon("fsync failed", errno, true);
  if (::close(fd) != 0) return abandon("close failed", errno, false);
  if (publish == Publish::kReplace) {
    if (::rename(temp_name.c_str(), path.c_str()) != 0) return abandon("rename failed", errno, false);
  } else {
    // link() refuses an existing target atomically, which rename() would silently replace.
    if (::link(temp_name.c_str(), path.c_str()) != 0) {
      const int error = errno;
      return abandon(error == EEXIST ? "the file exists already (recorded data is never overwritten)" : "link failed",
                     error, false);
    }
    ::unlink(temp_name.c_str());
  }
  if (!FsyncDirectory(directory)) return Failure("fsync of directory " + directory + " failed", path, errno);
  return Status::Ok();
}

Result<std::string> ReadFileCapped(const std::string& path, std::size_t max_bytes, bool* missing) {
  if (missing != nullptr) *missing = false;
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused just below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int error = errno;
    if (missing != nullptr) *missing = error == ENOENT;
    return Status::Error(ErrorCode::kInvalidInput, "cannot open " + path + ": " + std::strerror(error))
        .WithDetail(kErrnoDomain, error);
  }
  struct stat info {};
  std::string text, error;
  int error_number = 0;
  if (::fstat(fd, &info) != 0) {
    error_number = errno;
    error = "cannot stat " + path + ": " + std::strerror(error_number);
  } else if (!S_ISREG(info.st_mode)) {
    error = path + " is not a regular file";
  } else if (static_cast<unsigned long long>(info.st_size) > max_bytes) {
    error =
        path + " is " + std::to_string(info.st_size) + " bytes, more than the limit of " + std::to_string(max_bytes) +
        " bytes";
  } else {
    // One byte past the size from fstat, so that a file growing meanwhile is noticed.
    text.resize(static_cast<size_t>(info.st_size) + 1);
    size_t used = 0;
    while (used < text.size()) {
      const ssize_t n = ::read(fd, text.data() + used, text.size() - used);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        error_number = errno;
        error = "cannot read " + path + ": " + std::strerror(error_number);
        break;
      }
      if (n == 0) break;
      used += static_cast<size_t>(n);
      if (used == text.size() && used <= max_bytes) text.resize(std::min(text.size() * 2, max_bytes + 1));
    }
    text.resize(used);
    if (error.empty() && used > max_bytes) {
      error = path + " grew while it was read, to more than the limit of " + std::to_string(max_bytes) + " bytes";
    }
  }
  ::close(fd);
  if (error_number != 0) return Status::Error(ErrorCode::kInvalidInput, error).WithDetail(kErrnoDomain, error_number);
  if (!error.empty()) return Status::Error(ErrorCode::kInvalidInput, error);
  return text;
}

}  // namespace selfcal
