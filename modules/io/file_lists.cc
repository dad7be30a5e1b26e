#include "io/file_lists.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

namespace selfcal::io {

namespace {

bool IsNumber(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

// Numbers by value (no leading zeros: the shorter is smaller), then names.
bool KeyLess(const std::string& a, const std::string& b) {
  const bool na = IsNumber(a), nb = IsNumber(b);
  if (na && nb && a.size() != b.size()) return a.size() < b.size();
  if (na != nb) return na;  // numbered files first
  return a < b;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool IsRegularFile(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace

std::string FileStem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

std::string ImageKey(const std::string& path) {
  const std::string stem = FileStem(path);
  size_t end = stem.size();
  while (end > 0 && !std::isdigit(static_cast<unsigned char>(stem[end - 1]))) --end;
  if (end == 0) return stem;
  size_t begin = end;
  while (begin > 0 && std::isdigit(static_cast<unsigned char>(stem[begin - 1]))) --begin;
  while (begin + 1 < end && stem[begin] == '0') ++begin;
  return stem.substr(begin, end - begin);
}

const std::vector<std::string>& ImageExtensions() {
  static const std::vector<std::string> kExtensions = {".png", ".jpg", ".jpeg", ".pgm", ".ppm", ".bmp", ".tif", ".tiff"};
  return kExtensions;
}

Result<std::vector<std::string>> ListFiles(const std::string& spec, const std::vector<std::string>& extensions,
                                           const std::string& what) {
  std::vector<std::string> files;
  std::error_code ec;
  if (std::filesystem::is_directory(spec, ec)) {
    std::filesystem::directory_iterator it(spec, ec), end;
    if (ec) return Status::Error(ErrorCode::kInvalidInput, spec + ": cannot list the directory: " + ec.message());
    for (; it != end; it.increment(ec)) {
      if (ec) return Status::Error(ErrorCode::kInvalidInput, spec + ": cannot list the directory: " + ec.message());
      const std::string ext = Lower(it->path().extension().string());
      if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) continue;
      if (IsRegularFile(it->path().string())) files.push_back(it->path().string());
    }
  } else {
    glob_t matches{};
    const int rc = ::glob(spec.c_str(), GLOB_NOSORT, nullptr, &matches);
    for (size_t k = 0; rc == 0 && k < matches.gl_pathc; ++k) {
      if (IsRegularFile(matches.gl_pathv[k])) files.emplace_back(matches.gl_pathv[k]);
    }
    ::globfree(&matches);
  }
  if (files.empty()) {
    std::string exts;
    for (const std::string& e : extensions) exts += (exts.empty() ? "" : " ") + e;
    return Status::Error(ErrorCode::kInvalidInput,
                         spec + ": no " + what + " found (a directory holding " + exts + " files, or a glob)");
  }
  std::sort(files.begin(), files.end(), [](const std::string& a, const std::string& b) {
    const std::string ka = ImageKey(a), kb = ImageKey(b);
    if (ka != kb) return KeyLess(ka, kb);
    return a < b;
  });
  return files;
}

}  // namespace selfcal::io
