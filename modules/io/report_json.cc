#include "io/report_json.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include <nlohmann/json.hpp>

#include "base/json_lines.h"
#include "io/atomic_file.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

namespace {

// The index of the quote that closes the JSON string opening at text[open] (or text.size()).
size_t StringEnd(const std::string& text, size_t open) {
  for (size_t i = open + 1; i < text.size(); ++i) {
    if (text[i] == '\\') {
      ++i;
    } else if (text[i] == '"') {
      return i;
    }
  }
  return text.size();
}

// Nesting depth of a JSON text (brackets outside strings), so that deep documents are refused before
// parsing.
int JsonDepth(const std::string& text, size_t* offset) {
  int depth = 0, max_depth = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      i = StringEnd(text, i);
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        max_depth = depth;
        *offset = i;
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return max_depth;
}

// The line (from 1) of byte `offset` of `text`.
int LineAt(const std::string& text, size_t offset) {
  const size_t end = std::min(offset, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
}

// The first number outside strings that a double cannot hold (nlohmann's "number overflow" names no place):
// its text in *number and its line, or 0.
int OverflowingNumberLine(const std::string& text, std::string* number) {
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      i = StringEnd(text, i);
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      const size_t end = text.find_first_not_of("+-.0123456789eE", i);
      *number = text.substr(i, end == std::string::npos ? std::string::npos : end - i);
      if (!std::isfinite(std::strtod(number->c_str(), nullptr))) return LineAt(text, i);
      i = end == std::string::npos ? text.size() : end - 1;
    }
  }
  return 0;
}

}  // namespace

Status WriteJsonFile(const nlohmann::json& document, const std::string& path) {
  std::string text;
  try {
    text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::strict) + "\n";
  } catch (const std::exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot write " + path + ": " + e.what());
  }
  return WriteFileAtomically(path, text);
}

Result<nlohmann::json> ReadJsonFile(const std::string& path) {
  Result<std::string> text = ReadFileCapped(path, yaml::kMaxYamlBytes);
  if (!text.ok()) return text.status();
  size_t offset = 0;
  if (JsonDepth(*text, &offset) > yaml::kMaxYamlDepth) {
    return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(LineAt(*text, offset)) +
                                                       ": JSON nested deeper than " +
                                                       std::to_string(yaml::kMaxYamlDepth) + " levels");
  }
  try {
    nlohmann::json document = nlohmann::json::parse(*text);
    if (const std::optional<JsonDuplicateKey> duplicate = FindDuplicateJsonKey(*text)) {
      return Status::Error(ErrorCode::kInvalidInput,
                           path + ":" + std::to_string(duplicate->line) + ": " + DuplicateKeyProblem(*duplicate));
    }
    return document;
  } catch (const nlohmann::json::parse_error& e) {
    return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(LineAt(*text, e.byte > 0 ? e.byte - 1 : 0)) +
                                                       ": malformed JSON: " + e.what());
  } catch (const std::exception& e) {
    std::string number;
    if (const int line = OverflowingNumberLine(*text, &number); line > 0) {
      return Status::Error(ErrorCode::kInvalidInput, path + ":" + std::to_string(line) + ": the number " + number +
                                                         " is beyond the range of a double");
    }
    return Status::Error(ErrorCode::kInvalidInput, "cannot read JSON " + path + ": " + e.what());
  }
}

}  // namespace selfcal::io
