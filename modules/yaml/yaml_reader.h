// Module yaml (ARCHITECTURE.md): the strict YAML reader, uses only base; libyaml (its C event parser,
// yaml_parser_parse) private. Shared by io's files and capture's recorded-sequence index.
//
// Strict YAML reading: the only way selfcal reads a YAML file (C1-C3, C8, P8). Bottom layer (uses only
// base), so that io's files and capture's recorded-sequence index share one reader.
//
// Two layers:
//  1. LoadYamlFile / ParseYamlText turn bytes into a YamlNode tree with 1-based line numbers. Before
//     libyaml sees the text, the file is checked for size (<= kMaxYamlBytes, from stat, before
//     reading), UTF-8 validity and control bytes (also U+0085, U+2028 and U+2029, which libyaml would
//     count as line breaks); a UTF-8 BOM is dropped and CRLF / CR line ends become LF; an OpenCV
//     `%YAML:1.0` first line is read as a comment. The tree is built from libyaml's events, refusing as
//     its event arrives: nesting deeper than kMaxYamlDepth, anchors and aliases (no alias bombs), explicit
//     tags, non-scalar or duplicate map keys, more than kMaxYamlNodes nodes, and more than one document.
//     A plain ~, null, Null, NULL or empty value is a kNull node. Every refusal is a Status; the code is
//     always ErrorCode::kInvalidInput and the message names the file (and the line when known). YamlRules
//     sets the limits and the wording of the refusals.
//  2. Problems and MapReader (io/yaml_schema.h) check a tree against a schema.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::yaml {

inline constexpr std::size_t kMaxYamlBytes = 10u * 1024u * 1024u;  // 10 MiB
inline constexpr int kMaxYamlDepth = 64;                           // nested sequences and maps
inline constexpr std::size_t kMaxYamlNodes = 1000000;

// How refusals read. kUserFile (files people write: robot configs, observations, plans): "<problem> at
// FILE:LINE" with advice. kSequenceIndex (capture's recorded-sequence index, which selfcal writes
// itself): "FILE:LINE: <problem>" in the shorter words the index reader has always used.
enum class YamlWording { kUserFile, kSequenceIndex };

// What one kind of file may hold; the defaults are those of LoadYamlFile.
struct YamlRules {
  std::size_t max_bytes = kMaxYamlBytes;
  int max_depth = kMaxYamlDepth;  // nested sequences and maps
  std::size_t max_nodes = kMaxYamlNodes;
  YamlWording wording = YamlWording::kUserFile;
  // Explicit tags that start with this are accepted (and ignored): OpenCV's `!!opencv-matrix` is
  // "tag:yaml.org,2002:opencv-matrix". Empty: every explicit tag but `!` is refused.
  std::string accepted_tag_prefix;
};

struct YamlNode {
  enum class Kind { kNull, kScalar, kSequence, kMap };
  Kind kind = Kind::kNull;
  int line = 0;    // 1-based; for an empty map value, the line of its key
  int column = 0;  // 1-based
  std::string scalar;  // kScalar: the text (quotes and escapes already resolved)
  bool plain = true;   // kScalar: unquoted, so it may be read as a number
  std::vector<YamlNode> items;    // kSequence: the elements; kMap: the values, parallel to keys
  std::vector<std::string> keys;  // kMap: unique scalar keys, in file order
  std::vector<int> key_lines;     // kMap: 1-based line of each key

  bool IsMap() const { return kind == Kind::kMap; }
  bool IsSequence() const { return kind == Kind::kSequence; }
  bool IsScalar() const { return kind == Kind::kScalar; }
  bool IsNull() const { return kind == Kind::kNull; }
  // kMap: the value of `key`, or nullptr when absent.
  const YamlNode* Find(const std::string& key) const;
  // "map", "sequence", "string", "number-like scalar" or "empty value": for messages.
  const char* KindName() const;
};

struct YamlDocument {
  std::string path;  // as given; named in every message
  YamlNode root;     // kNull for a document without content
};

// Reads and parses one file. Errors (kInvalidInput): missing or unreadable file, not a regular file, too large,
// not UTF-8, empty, malformed YAML, limits above exceeded.
Result<YamlDocument> LoadYamlFile(const std::string& path);

// Parses text already in memory; `name` stands for the file in messages. Same checks as LoadYamlFile,
// with the limits and wording of `rules`.
Result<YamlDocument> ParseYamlText(const std::string& text, const std::string& name, const YamlRules& rules = {});

}  // namespace selfcal::yaml
