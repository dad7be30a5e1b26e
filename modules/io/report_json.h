// JSON result files. nlohmann::json is a public dependency of io so that callers build the document
// themselves; this file only writes and reads it safely.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "base/status.h"

namespace selfcal::io {

// Pretty-printed (2-space indent) with a final newline, written atomically (P4). Non-finite numbers
// become null (JSON has no NaN); invalid UTF-8 in a string is refused. ErrorCode::kInvalidInput on failure.
Status WriteJsonFile(const nlohmann::json& document, const std::string& path);

// Reads a JSON file with the same guards as YAML files: size cap (yaml/yaml_reader.h kMaxYamlBytes),
// nesting depth cap (kMaxYamlDepth), every parse error a Status naming the file and byte offset, a key
// given twice in one object refused naming the file and line.
Result<nlohmann::json> ReadJsonFile(const std::string& path);

}  // namespace selfcal::io
