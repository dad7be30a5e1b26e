#include "base/sha256.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <cstdint>

#include <nettle/sha2.h>

#include "base/atomic_file.h"

namespace selfcal {

namespace {

std::string Hex(const unsigned char* digest, unsigned int length) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex.push_back(kDigits[digest[i] >> 4]);
    hex.push_back(kDigits[digest[i] & 0xf]);
  }
  return hex;
}

struct ScopedFd {
  int fd;
  ~ScopedFd() { ::close(fd); }
};

Status FileError(const std::string& what, const std::string& path, int error) {
  return Status::Error(ErrorCode::kInvalidInput, what + " " + path + ": " + std::strerror(error)).WithDetail(kErrnoDomain, error);
}

}  // namespace

std::string Sha256Hex(std::string_view bytes) {
  sha256_ctx context;
  sha256_init(&context);
  sha256_update(&context, bytes.size(), reinterpret_cast<const uint8_t*>(bytes.data()));
  uint8_t digest[SHA256_DIGEST_SIZE];
  sha256_digest(&context, SHA256_DIGEST_SIZE, digest);
  return Hex(digest, SHA256_DIGEST_SIZE);
}

Result<std::string> Sha256OfFile(const std::string& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused just below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return FileError("cannot open", path, errno);
  const ScopedFd closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0) return FileError("cannot stat", path, errno);
  if (!S_ISREG(info.st_mode)) {
    return Status::Error(ErrorCode::kInvalidInput, path + " is not a regular file: cannot compute its SHA-256");
  }
  sha256_ctx context;
  sha256_init(&context);
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return FileError("cannot read", path, errno);
    if (n == 0) break;
    sha256_update(&context, static_cast<std::size_t>(n), reinterpret_cast<const uint8_t*>(buffer));
  }
  uint8_t digest[SHA256_DIGEST_SIZE];
  sha256_digest(&context, SHA256_DIGEST_SIZE, digest);
  return Hex(digest, SHA256_DIGEST_SIZE);
}

}  // namespace selfcal
