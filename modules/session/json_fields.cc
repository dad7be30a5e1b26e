#include "session/json_fields.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "base/terminal_text.h"

namespace selfcal::session {

using nlohmann::json;

JsonPath JsonPath::Member(const std::string& key) const {
  return {JsonLines::Member(pointer, key), name.empty() ? key : name + "." + key};
}

JsonPath JsonPath::Element(std::size_t index) const {
  return {JsonLines::Element(pointer, index), name + "[" + std::to_string(index) + "]"};
}

std::string JsonTypeName(const json& value) {
  if (value.is_number()) return "number";
  return value.type_name();
}

JsonFields::JsonFields(std::string_view text, std::string file) : text_(text), lines_(text), file_(std::move(file)) {}

std::optional<json> JsonFields::ParseObject() {
  json document = json::parse(text_, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded()) {
    const std::optional<JsonSyntaxError> error = FindJsonSyntaxError(text_);
    const std::string why = error ? error->reason : "unreadable";
    problems_.push_back(file_ + ":" + std::to_string(error ? error->line : 1) + ": not JSON: " + why);
    return std::nullopt;
  }
  if (!document.is_object()) {
    Add({}, "the document is not a JSON object (found " + JsonTypeName(document) + ")");
    return std::nullopt;
  }
  if (const std::optional<JsonDuplicateKey>& duplicate = lines_.duplicate()) {
    problems_.push_back(file_ + ":" + std::to_string(duplicate->line) + ": " + DuplicateKeyProblem(*duplicate));
    return std::nullopt;
  }
  return document;
}

std::string JsonFields::At(const JsonPath& path) const { return file_ + ":" + std::to_string(lines_.Line(path.pointer)); }

void JsonFields::Add(const JsonPath& path, const std::string& what) { problems_.push_back(At(path) + ": " + what); }

const json* JsonFields::Get(const json& object, const JsonPath& path, const std::string& key) {
  const auto it = object.find(key);
  if (it == object.end()) {
    Add(path, "missing key `" + key + "`" + (path.name.empty() ? "" : " in `" + path.name + "`"));
    return nullptr;
  }
  return &*it;
}

namespace {
std::string Quoted(const JsonPath& path) { return "`" + path.name + "`"; }
}  // namespace

bool JsonFields::GetInt(const json& object, const JsonPath& path, const std::string& key, int* out) {
  const json* value = Get(object, path, key);
  if (value == nullptr) return false;
  const JsonPath at = path.Member(key);
  const bool fits = value->is_number_unsigned()   ? value->get<std::uint64_t>() <= std::uint64_t{INT32_MAX}
                    : value->is_number_integer() ? value->get<std::int64_t>() >= INT32_MIN &&
                                                       value->get<std::int64_t>() <= INT32_MAX
                                                 : false;
  if (!fits) {
    const std::string found = value->is_number_integer() ? value->dump() : JsonTypeName(*value);
    Add(at, Quoted(at) + " must be an integer in [-2147483648, 2147483647] (found " + found + ")");
    return false;
  }
  *out = static_cast<int>(value->get<std::int64_t>());
  return true;
}

bool JsonFields::GetDouble(const json& object, const JsonPath& path, const std::string& key, double* out) {
  const json* value = Get(object, path, key);
  if (value == nullptr) return false;
  const JsonPath at = path.Member(key);
  if (!value->is_number() || !std::isfinite(value->get<double>())) {
    Add(at, Quoted(at) + " must be a finite number (found " + JsonTypeName(*value) + ")");
    return false;
  }
  *out = value->get<double>();
  return true;
}

bool JsonFields::GetString(const json& object, const JsonPath& path, const std::string& key, std::string* out) {
  const json* value = Get(object, path, key);
  if (value == nullptr) return false;
  const JsonPath at = path.Member(key);
  if (!value->is_string()) {
    Add(at, Quoted(at) + " must be a string (found " + JsonTypeName(*value) + ")");
    return false;
  }
  *out = value->get<std::string>();
  return true;
}

const json* JsonFields::GetArray(const json& object, const JsonPath& path, const std::string& key) {
  const json* value = Get(object, path, key);
  if (value == nullptr) return nullptr;
  const JsonPath at = path.Member(key);
  if (!value->is_array()) {
    Add(at, Quoted(at) + " must be an array (found " + JsonTypeName(*value) + ")");
    return nullptr;
  }
  return value;
}

void JsonFields::CheckKnown(const json& object, const JsonPath& path, const std::vector<std::string>& known) {
  for (const auto& item : object.items()) {
    if (std::find(known.begin(), known.end(), item.key()) == known.end()) {
      Add(path.Member(item.key()), "unknown key `" + TerminalSafe(item.key()) + "`" +
                                       (path.name.empty() ? "" : " in `" + path.name + "`"));
    }
  }
}

Status JsonFields::ToStatus() const {
  std::string text;
  for (const std::string& problem : problems_) text += (text.empty() ? "" : "; ") + problem;
  return Status::Error(ErrorCode::kInvalidInput, text);
}

}  // namespace selfcal::session
