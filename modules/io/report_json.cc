#include "io/report_json.h"

#include <optional>

#include <nlohmann/json.hpp>

#include "base/json_lines.h"
#include "io/atomic_file.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

namespace {

// Nesting depth of a JSON text (brackets outside strings), so that deep documents are refused before
// parsing.
int JsonDepth(const std::string& text, size_t* offset) {
  int depth = 0, max_depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
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
    return Status::Error(ErrorCode::kInvalidInput, path + ": JSON nested deeper than " + std::to_string(yaml::kMaxYamlDepth) +
                                               " levels at byte " + std::to_string(offset));
  }
  try {
    nlohmann::json document = nlohmann::json::parse(*text);
    if (const std::optional<JsonDuplicateKey> duplicate = FindDuplicateJsonKey(*text)) {
      return Status::Error(ErrorCode::kInvalidInput,
                           path + ":" + std::to_string(duplicate->line) + ": " + DuplicateKeyProblem(*duplicate));
    }
    return document;
  } catch (const nlohmann::json::parse_error& e) {
    return Status::Error(ErrorCode::kInvalidInput, "malformed JSON in " + path + " at byte " + std::to_string(e.byte) + ": " + e.what());
  } catch (const std::exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read JSON " + path + ": " + e.what());
  }
}

}  // namespace selfcal::io
