#include "io/opencv_lines.h"

#include <algorithm>
#include <regex>
#include <sstream>

namespace selfcal::io {

namespace {

// Whether `rest` (a line after its indentation) starts with `key` as a map key in one of FileStorage's
// formats.
bool StartsWithKey(const std::string& rest, const std::string& key) {
  auto colon_after = [&](size_t at) {
    while (at < rest.size() && (rest[at] == ' ' || rest[at] == '\t')) ++at;
    return at < rest.size() && rest[at] == ':';
  };
  if (rest.compare(0, key.size(), key) == 0 && colon_after(key.size())) return true;
  for (const char quote : {'"', '\''}) {
    const std::string quoted = quote + key + quote;
    if (rest.compare(0, quoted.size(), quoted) == 0 && colon_after(quoted.size())) return true;
  }
  const std::string tag = "<" + key;
  return rest.compare(0, tag.size(), tag) == 0 && rest.size() > tag.size() &&
         std::string(" \t>/").find(rest[tag.size()]) != std::string::npos;
}

}  // namespace

OpenCvLines::OpenCvLines(const std::string& text, const std::vector<std::string>& top_keys) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines_.push_back(line);
  int first = 0;
  for (const std::string& key : top_keys) {
    const int line = Find(key);
    if (line > 0 && (first == 0 || line < first)) first = line;
  }
  if (first > 0) document_ = first;
}

int OpenCvLines::Key(const std::string& key) const {
  const int line = Find(key);
  return line > 0 ? line : document_;
}

int OpenCvLines::Find(const std::string& key) const {
  int best = 0;
  size_t best_indent = std::string::npos;
  for (size_t i = 0; i < lines_.size(); ++i) {
    const size_t indent = lines_[i].find_first_not_of(" \t{,");
    if (indent == std::string::npos || indent >= best_indent) continue;
    if (StartsWithKey(lines_[i].substr(indent), key)) best = static_cast<int>(i) + 1, best_indent = indent;
  }
  if (best > 0) return best;
  const std::string quoted = "\"" + key + "\"";
  for (size_t i = 0; i < lines_.size(); ++i) {
    if (lines_[i].find(quoted) != std::string::npos) return static_cast<int>(i) + 1;
  }
  return 0;
}

std::optional<OpenCvParseError> ParseOpenCvError(const std::string& what) {
  static const std::regex kLine("'\\((\\d{1,9})\\): ([^']*)'");
  std::smatch match;
  if (!std::regex_search(what, match, kLine)) return std::nullopt;
  return OpenCvParseError{std::max(1, std::stoi(match[1].str())), match[2].str()};
}

}  // namespace selfcal::io
