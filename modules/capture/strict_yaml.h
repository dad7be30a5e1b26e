// Internal to capture: a small strict YAML tree for the recorded-sequence index (RELIABILITY.md C8, V8).
//
// capture sits in layer 2 and may not use io's reader (layer 5), so this is a reduced copy of its rules:
// size cap, UTF-8 without control bytes, flow collections nested at most kMaxDepth deep (checked before
// yaml-cpp scans), block nesting refused past kMaxDepth from the event handler (so yaml-cpp never
// recurses further), no anchors, aliases or explicit tags, no duplicate or non-scalar keys, one
// document. Every yaml-cpp exception becomes a Status naming the file and line.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::capture::internal {

struct YamlTree {
  enum class Kind { kNull, kScalar, kSequence, kMap };
  Kind kind = Kind::kNull;
  int line = 0;                   // 1-based
  std::string scalar;             // kScalar
  bool plain = true;              // kScalar: unquoted
  std::vector<YamlTree> items;    // kSequence elements; kMap values (parallel to keys)
  std::vector<std::string> keys;  // kMap

  const YamlTree* Find(const std::string& key) const;
  const char* KindName() const;
};

inline constexpr int kMaxYamlDepth = 8;
inline constexpr std::size_t kMaxYamlNodes = 2000000;

// Parses `text`, naming `name` in every message. The error Status is plain (no capture detail); the
// caller wraps it in its own CaptureError.
Result<YamlTree> ParseStrictYaml(const std::string& text, const std::string& name);

}  // namespace selfcal::capture::internal
