#include "base/sha256.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include <openssl/evp.h>

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
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  SELFCAL_CHECK(EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) == 1,
                "OpenSSL SHA-256 failed");
  return Hex(digest, length);
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
  const std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> context(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  SELFCAL_CHECK(context != nullptr && EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) == 1,
                "OpenSSL SHA-256 failed");
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return FileError("cannot read", path, errno);
    if (n == 0) break;
    SELFCAL_CHECK(EVP_DigestUpdate(context.get(), buffer, static_cast<std::size_t>(n)) == 1, "OpenSSL SHA-256 failed");
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  SELFCAL_CHECK(EVP_DigestFinal_ex(context.get(), digest, &length) == 1, "OpenSSL SHA-256 failed");
  return Hex(digest, length);
}

}  // namespace selfcal
