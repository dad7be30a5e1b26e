#include "yaml/yaml_reader.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <new>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include "base/atomic_file.h"

namespace selfcal::yaml {

const YamlNode* YamlNode::Find(const std::string& key) const {
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] == key) return &items[i];
  }
  return nullptr;
}

const char* YamlNode::KindName() const {
  switch (kind) {
    case Kind::kNull: return "an empty value";
    case Kind::kScalar: return plain ? "a scalar" : "a quoted string";
    case Kind::kSequence: return "a sequence";
    case Kind::kMap: return "a map";
  }
  return "?";
}

namespace {

Status UsageError(const std::string& message) { return Status::Error(ErrorCode::kInvalidInput, message); }

std::string At(const std::string& name, int line) { return name + ":" + std::to_string(line); }

bool Terse(const YamlRules& rules) { return rules.wording == YamlWording::kSequenceIndex; }

// A refusal located in the file: "<problem> at FILE:LINE", or "FILE:LINE: <problem>" when terse.
Status Refusal(const YamlRules& rules, const std::string& name, int line, const std::string& problem) {
  return UsageError(Terse(rules) ? At(name, line) + ": " + problem : problem + " at " + At(name, line));
}

// A limit of ours hit while yaml-cpp parses: thrown from the event handler, so yaml-cpp never recurses
// past the depth limit.
class TreeError : public std::runtime_error {
 public:
  TreeError(int line, const std::string& message) : std::runtime_error(message), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

int Line(const YAML::Mark& mark) { return mark.line + 1; }

// Decodes one UTF-8 sequence at text[i]; returns its length, or 0 when invalid (overlong, surrogate,
// beyond U+10FFFF, truncated).
int DecodeUtf8(const std::string& text, size_t i, unsigned* code_point) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned b0 = byte(i);
  int length = 0;
  unsigned cp = 0, min = 0;
  if (b0 < 0x80) {
    *code_point = b0;
    return 1;
  } else if ((b0 & 0xE0) == 0xC0) {
    length = 2, cp = b0 & 0x1F, min = 0x80;
  } else if ((b0 & 0xF0) == 0xE0) {
    length = 3, cp = b0 & 0x0F, min = 0x800;
  } else if ((b0 & 0xF8) == 0xF0) {
    length = 4, cp = b0 & 0x07, min = 0x10000;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (int k = 1; k < length; ++k) {
    const unsigned b = byte(i + k);
    if ((b & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  *code_point = cp;
  return length;
}

// YAML 1.2 c-printable plus line breaks.
bool Printable(unsigned cp) {
  if (cp == 0x09 || cp == 0x0A || cp == 0x0D || cp == 0x85) return true;
  if (cp >= 0x20 && cp <= 0x7E) return true;
  if (cp >= 0xA0 && cp <= 0xD7FF) return true;
  if (cp >= 0xE000 && cp <= 0xFFFD) return true;
  return cp >= 0x10000 && cp <= 0x10FFFF;
}

// A character that is not printable UTF-8: `byte` starts an invalid sequence (!decoded) or the code
// point is a control character.
Status BadCharacter(const YamlRules& rules, const std::string& name, int line, unsigned char byte, bool decoded,
                    unsigned code_point) {
  char hex[12];
  std::snprintf(hex, sizeof(hex), "0x%02X", byte);
  if (Terse(rules)) return UsageError(At(name, line) + ": invalid byte " + hex + " (binary or corrupted file?)");
  std::string what = "invalid UTF-8 (byte " + std::string(hex) + ")";
  if (decoded) {
    std::snprintf(hex, sizeof(hex), "U+%04X", code_point);
    what = "control character " + std::string(hex);
  }
  return UsageError(what + " at " + At(name, line) + "; is this a binary file? selfcal reads UTF-8 YAML");
}

// Checks encoding and characters, drops a UTF-8 BOM and turns CRLF and lone CR into LF. The terse
// wording names a UTF-16 or UTF-32 byte order mark as the invalid byte it starts with.
Status Normalise(const YamlRules& rules, const std::string& name, std::string* text) {
  const std::string& t = *text;
  const auto starts = [&](const char* prefix, size_t n) { return t.size() >= n && std::memcmp(t.data(), prefix, n) == 0; };
  if (!Terse(rules) && (starts("\x00\x00\xFE\xFF", 4) || starts("\xFF\xFE\x00\x00", 4) || starts("\xFE\xFF", 2) || starts("\xFF\xFE", 2))) {
    return UsageError("a UTF-16 or UTF-32 byte order mark at " + At(name, 1) + ": the file is not UTF-8; save it as UTF-8");
  }
  const size_t start = starts("\xEF\xBB\xBF", 3) ? 3 : 0;
  std::string out;
  out.reserve(t.size());
  int line = 1;
  for (size_t i = start; i < t.size();) {
    unsigned cp = 0;
    const int length = DecodeUtf8(t, i, &cp);
    if (length == 0 || !Printable(cp)) {
      return BadCharacter(rules, name, line, static_cast<unsigned char>(t[i]), length != 0, cp);
    }
    if (cp == '\r') {
      out.push_back('\n');
      ++line;
      i += (i + 1 < t.size() && t[i + 1] == '\n') ? 2 : 1;
      continue;
    }
    if (cp == '\n') ++line;
    out.append(t, i, length);
    i += length;
  }
  *text = std::move(out);
  return Status::Ok();
}

// Flow collections ([ and {) nested deeper than the limit, found before yaml-cpp parses anything.
// Quotes and comments are skipped; brackets inside plain scalars may over-count, which only matters for
// files that are suspicious anyway.
Status PrescanFlowDepth(const YamlRules& rules, const std::string& name, const std::string& text) {
  int depth = 0, line = 1;
  char quote = 0;
  char previous = '\n';
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (quote == '"') {
      if (c == '\\') {
        ++i;
        if (i < text.size() && text[i] == '\n') ++line;
      } else if (c == '"') {
        quote = 0;
      }
    } else if (quote == '\'') {
      if (c == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;
      } else if (c == '\'') {
        quote = 0;
      }
    } else if (c == '#' && (previous == ' ' || previous == '\t' || previous == '\n')) {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if ((c == '"' || c == '\'') && std::strchr(" \t\n[{,:", previous) != nullptr) {
      quote = c;
    } else if (c == '[' || c == '{') {
      if (++depth > rules.max_depth) {
        return Refusal(rules, name, line, "YAML nested deeper than " + std::to_string(rules.max_depth) + " levels");
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    previous = c;
  }
  return Status::Ok();
}

class TreeBuilder : public YAML::EventHandler {
 public:
  TreeBuilder(const YamlRules& rules, YamlNode* root) : rules_(rules), terse_(Terse(rules)), root_(root) {}

  void OnDocumentStart(const YAML::Mark& mark) override {
    if (++documents_ > 1) {
      throw TreeError(Line(mark), terse_ ? "more than one YAML document" : "more than one YAML document (a second `---`)");
    }
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    CheckAnchor(mark, anchor);
    Add(MakeNode(YamlNode::Kind::kNull, mark));
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    throw TreeError(Line(mark), terse_ ? "YAML aliases are not allowed in a sequence index"
                                       : "YAML aliases (*name) are not supported; write the values out");
  }
  void OnAnchor(const YAML::Mark& mark, const std::string&) override {
    throw TreeError(Line(mark), terse_ ? kTerseAnchors : "YAML anchors (&name) are not supported; write the values out");
  }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                const std::string& value) override {
    CheckAnchor(mark, anchor);
    if (tag != "?" && tag != "!") RefuseTag(mark, tag);
    YamlNode node = MakeNode(YamlNode::Kind::kScalar, mark);
    node.scalar = value;
    node.plain = tag == "?";
    Add(std::move(node));
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    StartCollection(YamlNode::Kind::kSequence, mark, tag, anchor);
  }
  void OnSequenceEnd() override { stack_.pop_back(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    StartCollection(YamlNode::Kind::kMap, mark, tag, anchor);
  }
  void OnMapEnd() override { stack_.pop_back(); }

 private:
  struct Frame {
    YamlNode* node;
    std::unordered_set<std::string> keys;  // for maps: duplicate detection in O(1)
  };

  static YamlNode MakeNode(YamlNode::Kind kind, const YAML::Mark& mark) {
    YamlNode node;
    node.kind = kind;
    node.line = Line(mark);
    node.column = mark.column + 1;
    return node;
  }

  static constexpr const char* kTerseAnchors = "YAML anchors are not allowed in a sequence index";

  void CheckAnchor(const YAML::Mark& mark, YAML::anchor_t anchor) const {
    if (anchor != YAML::NullAnchor) {
      throw TreeError(Line(mark), terse_ ? kTerseAnchors : "YAML anchors (&name) are not supported");
    }
  }

  [[noreturn]] void RefuseTag(const YAML::Mark& mark, const std::string& tag) const {
    throw TreeError(Line(mark), "explicit YAML tags (" + tag + ") are not " + (terse_ ? "allowed" : "supported"));
  }

  void StartCollection(YamlNode::Kind kind, const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor) {
    CheckAnchor(mark, anchor);
    if (tag != "?" && tag != "!" && !tag.empty()) RefuseTag(mark, tag);
    YamlNode* node = Add(MakeNode(kind, mark));
    if (static_cast<int>(stack_.size()) >= rules_.max_depth) {
      throw TreeError(Line(mark), "YAML nested deeper than " + std::to_string(rules_.max_depth) + " levels");
    }
    stack_.push_back(Frame{node, {}});
  }

  // Attaches a node to the collection being built; returns where it now lives (nullptr for map keys).
  // Pointers stay valid: a parent's item vector grows only after the previous child is complete.
  YamlNode* Add(YamlNode node) {
    if (++count_ > rules_.max_nodes) {
      throw TreeError(node.line, "more than " + std::to_string(rules_.max_nodes) + " YAML nodes");
    }
    if (stack_.empty()) {
      *root_ = std::move(node);
      return root_;
    }
    Frame& frame = stack_.back();
    YamlNode* parent = frame.node;
    if (parent->IsSequence()) {
      parent->items.push_back(std::move(node));
      return &parent->items.back();
    }
    if (parent->keys.size() == parent->items.size()) {  // this node is a key
      if (!node.IsScalar()) {
        throw TreeError(node.line, terse_          ? "map keys must be plain strings"
                                   : node.IsNull() ? "empty map key"
                                                   : "map keys must be plain strings, not collections");
      }
      if (!frame.keys.insert(node.scalar).second) {
        throw TreeError(node.line, "duplicate key `" + node.scalar + "`");
      }
      parent->keys.push_back(node.scalar);
      parent->key_lines.push_back(node.line);
      return nullptr;
    }
    if (node.IsNull()) node.line = parent->key_lines.back();
    parent->items.push_back(std::move(node));
    return &parent->items.back();
  }

  const YamlRules& rules_;
  const bool terse_;
  YamlNode* root_;
  std::vector<Frame> stack_;
  size_t count_ = 0;
  int documents_ = 0;
};

}  // namespace

Result<YamlDocument> ParseYamlText(const std::string& text_in, const std::string& name, const YamlRules& rules) {
  if (text_in.size() > rules.max_bytes) {
    const int line = 1 + static_cast<int>(std::count(text_in.begin(), text_in.begin() + rules.max_bytes, '\n'));
    return UsageError("the file is larger than " + std::to_string(rules.max_bytes) + " bytes (the limit falls at " +
                      At(name, line) + ")");
  }
  std::string text = text_in;
  if (Status s = Normalise(rules, name, &text); !s.ok()) return s;
  if (Status s = PrescanFlowDepth(rules, name, text); !s.ok()) return s;

  YamlDocument doc;
  doc.path = name;
  bool found = false;
  try {
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    TreeBuilder builder(rules, &doc.root);
    found = parser.HandleNextDocument(builder);
    if (found) parser.HandleNextDocument(builder);  // a second document throws in OnDocumentStart
  } catch (const TreeError& e) {
    return Refusal(rules, name, e.line(), e.what());
  } catch (const YAML::Exception& e) {
    const std::string where = e.mark.is_null() ? name : At(name, Line(e.mark));
    return UsageError("malformed YAML at " + where + ": " + e.msg);
  } catch (const std::bad_alloc&) {
    return UsageError("out of memory while parsing " + name);
  } catch (const std::exception& e) {
    return UsageError("cannot parse " + name + ": " + e.what());
  } catch (...) {
    return UsageError("cannot parse " + name + ": unknown error");
  }
  if (!found) return UsageError("no YAML document at " + At(name, 1) + " (the file is empty or holds only comments)");
  return doc;
}

Result<YamlDocument> LoadYamlFile(const std::string& path) {
  Result<std::string> text = ReadFileCapped(path, kMaxYamlBytes);
  if (!text.ok()) return text.status();
  return ParseYamlText(*text, path);
}

}  // namespace selfcal::yaml
