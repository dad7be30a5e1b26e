// Typed reading of the members of a session's JSON files (setup.json, session.json) with refusals that
// name the file and line: "<file>:<line>: `camera.fx_px` must be a number (found string)". The lines come
// from base/json_lines.h (nlohmann::json keeps none); a missing key is named at the line of the object
// that lacks it.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/json_lines.h"
#include "base/status.h"

namespace selfcal::session {

// Where a value is: its JSON pointer (for the line) and its name as messages show it (`camera.fx_px`,
// `inputs[2].name`; "" the document).
struct JsonPath {
  std::string pointer;
  std::string name;

  JsonPath Member(const std::string& key) const;
  JsonPath Element(std::size_t index) const;
};

class JsonFields {
 public:
  // `text` the document (JSON or not), `file` its name in messages.
  JsonFields(std::string_view text, std::string file);

  // Parses the text: the document when it is a JSON object that repeats no key in any of its objects;
  // otherwise nullopt after a problem ("<file>:<line>: not JSON: <why>", "... is not a JSON object (found
  // array)", "<file>:<line>: `camera.fx_px` is given twice (lines 4 and 9) ...").
  std::optional<nlohmann::json> ParseObject();

  // "<file>:<line>" of the value at `path`.
  std::string At(const JsonPath& path) const;
  // Adds the problem "<file>:<line of path>: <what>".
  void Add(const JsonPath& path, const std::string& what);

  // The member `key` of the object at `path`, or null after the problem "missing key `key`".
  const nlohmann::json* Get(const nlohmann::json& object, const JsonPath& path, const std::string& key);
  // The member as an int (an integer in int's range), a finite double, a string, an array; false after a
  // problem naming it (missing, or its type: "must be an integer (found string)").
  bool GetInt(const nlohmann::json& object, const JsonPath& path, const std::string& key, int* out);
  bool GetDouble(const nlohmann::json& object, const JsonPath& path, const std::string& key, double* out);
  bool GetString(const nlohmann::json& object, const JsonPath& path, const std::string& key, std::string* out);
  const nlohmann::json* GetArray(const nlohmann::json& object, const JsonPath& path, const std::string& key);
  // Adds "unknown key `k`" for every member of the object at `path` not in `known`.
  void CheckKnown(const nlohmann::json& object, const JsonPath& path, const std::vector<std::string>& known);

  bool ok() const { return problems_.empty(); }
  const std::vector<std::string>& problems() const { return problems_; }
  // kInvalidInput with the problems joined by "; ", each naming file and line.
  Status ToStatus() const;

 private:
  std::string_view text_;
  JsonLines lines_;
  std::string file_;
  std::vector<std::string> problems_;
};

// The JSON type of `value` as messages name it ("string", "array", "number", ...).
std::string JsonTypeName(const nlohmann::json& value);

}  // namespace selfcal::session
