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

// Names in natural order: runs of digits by their value ("pose_2" before "pose_10"), the rest by character
// ("s1_pose_11" before "s3_pose_00"); names that tie so ("p01", "p1") by character.
bool NaturalLess(const std::string& a, const std::string& b) {
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (digit(a[i]) && digit(b[j])) {
      size_t ie = i, je = j;
      while (ie < a.size() && digit(a[ie])) ++ie;
      while (je < b.size() && digit(b[je])) ++je;
      size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int c = a.compare(is, ie - is, b, js, je - js);
      if (c != 0) return c < 0;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  if ((i < a.size()) != (j < b.size())) return j < b.size();
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

const std::vector<std::string>& PoseFileExtensions() {
  static const std::vector<std::string> kExtensions = {".yaml", ".yml", ".json"};
  return kExtensions;
}

namespace {

bool HasExtension(const std::filesystem::path& path, const std::vector<std::string>& extensions) {
  const std::string ext = Lower(path.extension().string());
  return std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

// The regular files of `folder` with one of `extensions`, sorted by name.
std::vector<std::string> FilesIn(const std::filesystem::path& folder, const std::vector<std::string>& extensions,
                                 std::error_code* ec) {
  std::vector<std::string> files;
  for (std::filesystem::directory_iterator it(folder, *ec), end; !*ec && it != end; it.increment(*ec)) {
    if (HasExtension(it->path(), extensions) && IsRegularFile(it->path().string())) files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// "image.png" or "none" or "a.png and b.png": what a folder holds of one kind.
std::string Holding(const std::vector<std::string>& files) {
  if (files.empty()) return "none";
  std::string out;
  for (const std::string& f : files) out += (out.empty() ? "" : " and ") + std::filesystem::path(f).filename().string();
  return out;
}

}  // namespace

bool IsPoseFolderDirectory(const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return false;
  bool folders = false;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) folders = true;
    if (HasExtension(it->path(), ImageExtensions()) && IsRegularFile(it->path().string())) return false;
  }
  return folders && !ec;
}

Result<std::vector<PoseFolder>> ListPoseFolders(const std::string& dir) {
  std::error_code ec;
  std::vector<std::filesystem::path> folders;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) folders.push_back(it->path());
  }
  if (ec) return Status::Error(ErrorCode::kInvalidInput, dir + ": cannot list the directory: " + ec.message());
  std::vector<PoseFolder> out;
  std::string problems;
  for (const std::filesystem::path& folder : folders) {
    const std::vector<std::string> images = FilesIn(folder, ImageExtensions(), &ec);
    const std::vector<std::string> poses = FilesIn(folder, PoseFileExtensions(), &ec);
    if (ec) return Status::Error(ErrorCode::kInvalidInput, folder.string() + ": cannot list the folder: " + ec.message());
    if (images.size() != 1 || poses.size() != 1) {
      problems += "\n  - " + folder.string() + ": holds " + Holding(images) + " as its image and " + Holding(poses) +
                  " as its pose file; each pose's folder holds one image and one pose file (.json, .yaml or .yml)";
      continue;
    }
    out.push_back({folder.filename().string(), images[0], poses[0]});
  }
  if (!problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, dir + ": a folder per pose expected:" + problems);
  }
  if (out.empty()) return Status::Error(ErrorCode::kInvalidInput, dir + ": no pose folders found");
  std::sort(out.begin(), out.end(), [](const PoseFolder& a, const PoseFolder& b) { return NaturalLess(a.id, b.id); });
  return out;
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
