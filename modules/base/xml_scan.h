// A cheap, non-recursive scan of an XML text before a recursive parser sees it (C8).
//
// tinyxml (urdfdom's parser), OpenCV's FileStorage XML reader and a tree of nested elements all recurse
// once per level: 100,000 nested elements end the process with a stack overflow. ScanXml walks the text
// once with an explicit stack of element names and refuses, naming `name` and the line, a text that is
// larger than the limit, nests deeper than the limit, or is not well-formed in the ways that matter to
// the nesting (a tag, comment, CDATA section, declaration or DOCTYPE never closed; a closing tag that
// does not match the open element; an element never closed; text outside the root element is left to
// the parser). Optionally it also refuses invalid UTF-8 and repeated sibling elements (a key given twice
// in an OpenCV FileStorage XML, where the last one would win), both by line.
//
// What it does not do: check attribute syntax, entities or names beyond where a tag ends; the parser that
// follows does that, on a text now known to be shallow.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal {

inline constexpr int kMaxXmlDepth = 64;  // nested elements; URDFs and camera files use fewer than 10

struct XmlScanLimits {
  std::string kind;  // what the file is, for messages: "a URDF", "a ViSP camera file"
  std::size_t max_bytes = 16u << 20;
  int max_depth = kMaxXmlDepth;
  bool require_utf8 = false;
  // Sibling elements of the same name are refused, except those named in `repeatable`.
  bool refuse_repeated_siblings = false;
  std::vector<std::string> repeatable;
};

// Ok, or ErrorCode::kInvalidInput with "<name>:<line>: <what>" (the size refusal names the file's size and
// the limit).
Status ScanXml(const std::string& text, const std::string& name, const XmlScanLimits& limits);

// The 1-based line of the first invalid UTF-8 sequence of `text`, or 0 when it is valid UTF-8 (no
// overlong forms, surrogates or code points above U+10FFFF).
int FirstInvalidUtf8Line(const std::string& text);

}  // namespace selfcal
