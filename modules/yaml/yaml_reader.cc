#include "yaml/yaml_reader.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <new>
#include <unordered_set>

#include <yaml.h>

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

std::string At(const std::string& name, int line) { return name + ":" + std::to_string(line); }

bool Terse(const YamlRules& rules) { return rules.wording == YamlWording::kSequenceIndex; }

// A refusal located in the file: "<problem> at FILE:LINE", or "FILE:LINE: <problem>" when terse.
Status Refusal(const YamlRules& rules, const std::string& name, int line, const std::string& problem) {
  return Status::InvalidInput(Terse(rules) ? At(name, line) + ": " + problem : problem + " at " + At(name, line));
}

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
// point is a control character or a Unicode line break.
Status BadCharacter(const YamlRules& rules, const std::string& name, int line, unsigned char byte, bool decoded,
                    unsigned code_point) {
  char hex[12];
  std::snprintf(hex, sizeof(hex), "0x%02X", byte);
  if (Terse(rules))
    return Status::InvalidInput(At(name, line) + ": invalid byte " + hex + " (binary or corrupted file?)");
  std::string what = "invalid UTF-8 (byte " + std::string(hex) + ")";
  if (decoded) {
    std::snprintf(hex, sizeof(hex), "U+%04X", code_point);
    if (code_point == 0x2028 || code_point == 0x2029) {
      return Status::InvalidInput(std::string(code_point == 0x2028 ? "a line" : "a paragraph") + " separator " + hex +
                                  " at " + At(name, line) +
                                  ": YAML would read it as a line break that editors do not show; end lines with LF");
    }
    what = "control character " + std::string(hex);
  }
  return Status::InvalidInput(what + " at " + At(name, line) + "; is this a binary file? selfcal reads UTF-8 YAML");
}

// True for the bytes of a printable ASCII character or a tab or LF, which need no further check.
bool PlainAscii(unsigned char c) { return (c >= 0x20 && c < 0x7F) || c == '\t' || c == '\n'; }

// Checks encoding and characters, drops a UTF-8 BOM and turns CRLF and lone CR into LF. U+0085 (NEL),
// U+2028 and U+2029 are refused: libyaml reads them as line breaks, which would put every later line
// number out of step with the LF lines counted here and shown by editors. The terse wording names a
// UTF-16 or UTF-32 byte order mark as the invalid byte it starts with.
Status Normalise(const YamlRules& rules, const std::string& name, std::string* text) {
  std::string& t = *text;
  const auto starts = [&](const char* prefix, size_t n) { return t.size() >= n && std::memcmp(t.data(), prefix, n) == 0; };
  if (!Terse(rules) && (starts("\x00\x00\xFE\xFF", 4) || starts("\xFF\xFE\x00\x00", 4) || starts("\xFE\xFF", 2) || starts("\xFF\xFE", 2))) {
    return Status::InvalidInput("a UTF-16 or UTF-32 byte order mark at " + At(name, 1) +
                                ": the file is not UTF-8; save it as UTF-8");
  }
  if (starts("\xEF\xBB\xBF", 3)) t.erase(0, 3);
  bool has_cr = false;
  int line = 1;
  for (size_t i = 0; i < t.size();) {
    const unsigned char c = static_cast<unsigned char>(t[i]);
    if (PlainAscii(c)) {
      line += c == '\n';
      ++i;
      continue;
    }
    unsigned cp = 0;
    const int length = DecodeUtf8(t, i, &cp);
    if (length == 0 || !Printable(cp) || cp == 0x85 || cp == 0x2028 || cp == 0x2029) {
      return BadCharacter(rules, name, line, c, length != 0, cp);
    }
    if (cp == '\r') {
      has_cr = true;
      line += i + 1 == t.size() || t[i + 1] != '\n';  // a CRLF counts at its LF
    }
    i += length;
  }
  if (has_cr) {  // CRLF -> LF, a lone CR -> LF
    size_t out = 0;
    for (size_t i = 0; i < t.size(); ++i) {
      if (t[i] == '\r' && i + 1 < t.size() && t[i + 1] == '\n') continue;
      t[out++] = t[i] == '\r' ? '\n' : t[i];
    }
    t.resize(out);
  }
  return Status::Ok();
}

// The character at a libyaml mark (0-based line and column, in characters), or 0 past the text. `text` has
// only LF line ends (Normalise).
char32_t CharacterAt(const std::string& text, const yaml_mark_t& mark) {
  size_t i = 0;
  for (size_t line = 0; line < mark.line; ++line) {
    i = text.find('\n', i);
    if (i == std::string::npos) return 0;
    ++i;
  }
  unsigned cp = 0;
  for (size_t column = 0; i < text.size(); ++column) {
    const int length = DecodeUtf8(text, i, &cp);
    if (length == 0) return 0;
    if (column == mark.column) return cp;
    i += length;
  }
  return 0;
}

// Owns a libyaml parser reading `text` (which must outlive it) and the event last parsed.
class EventSource {
 public:
  explicit EventSource(const std::string& text) : text_(text) {
    ok_ = yaml_parser_initialize(&parser_) != 0;
    if (!ok_) return;
    yaml_parser_set_input_string(&parser_, reinterpret_cast<const unsigned char*>(text.data()), text.size());
    yaml_parser_set_encoding(&parser_, YAML_UTF8_ENCODING);
  }
  ~EventSource() {
    if (has_event_) yaml_event_delete(&event_);
    if (ok_) yaml_parser_delete(&parser_);
  }
  EventSource(const EventSource&) = delete;
  EventSource& operator=(const EventSource&) = delete;

  // The next event, or nullptr on a parse error (then see Problem()).
  const yaml_event_t* Next() {
    if (has_event_) yaml_event_delete(&event_);
    has_event_ = ok_ && yaml_parser_parse(&parser_, &event_) != 0;
    return has_event_ ? &event_ : nullptr;
  }

  int ProblemLine() const { return static_cast<int>(parser_.problem_mark.line) + 1; }

  // Why Next() failed: "malformed YAML at FILE:LINE: <libyaml's problem> (<its context>)". A simple key
  // without its `:` is found only on a later line: the message then names the key's line.
  Status Problem(const std::string& name) const {
    if (!ok_ || parser_.error == YAML_MEMORY_ERROR) return Status::InvalidInput("out of memory while parsing " + name);
    const std::string problem = parser_.problem != nullptr ? parser_.problem : "unknown problem";
    if (parser_.error == YAML_READER_ERROR) return Status::InvalidInput("malformed YAML in " + name + ": " + problem);
    const std::string context = parser_.context != nullptr ? parser_.context : "";
    const int context_line = static_cast<int>(parser_.context_mark.line) + 1;
    const int line = context == "while scanning a simple key" ? context_line : ProblemLine();
    std::string message = "malformed YAML at " + At(name, line) + ": " + problem;
    if (!context.empty()) message += " (" + context + (context_line != line ? " at line " + std::to_string(context_line) : "") + ")";
    if (problem.find("tab") == std::string::npos && CharacterAt(text_, parser_.problem_mark) == U'\t') message += "; a tab where YAML wants spaces";
    return Status::InvalidInput(message);
  }

 private:
  const std::string& text_;
  yaml_parser_t parser_{};
  yaml_event_t event_{};
  bool ok_ = false;
  bool has_event_ = false;
};

// A refusal of ours while the tree is built: where and what.
struct TreeError {
  int line = 0;
  std::string message;
};

// A plain scalar that YAML reads as null (as yaml-cpp did): an empty value, ~, null, Null or NULL.
bool IsNull(const char* value, size_t length) {
  if (length == 0) return true;
  if (length == 1) return value[0] == '~';
  return length == 4 && (std::memcmp(value, "null", 4) == 0 || std::memcmp(value, "Null", 4) == 0 ||
                         std::memcmp(value, "NULL", 4) == 0);
}

std::string Text(const yaml_char_t* text) { return text != nullptr ? reinterpret_cast<const char*>(text) : ""; }

// Builds the tree from libyaml's events, refusing what the rules forbid as soon as its event arrives (so a
// deep nesting stops at the limit).
class TreeBuilder {
 public:
  TreeBuilder(const YamlRules& rules, YamlNode* root) : rules_(rules), terse_(Terse(rules)), root_(root) {}

  // Handles one event; false with `error` set when the text breaks a rule.
  bool Handle(const yaml_event_t& event, TreeError* error) {
    const yaml_mark_t& mark = event.start_mark;
    switch (event.type) {
      case YAML_DOCUMENT_START_EVENT:
        if (++documents_ > 1) {
          return Fail(error, mark, terse_ ? "more than one YAML document" : "more than one YAML document (a second `---`)");
        }
        return true;
      case YAML_DOCUMENT_END_EVENT:
        document_ended_ = true;
        return true;
      case YAML_ALIAS_EVENT:
        return Fail(error, mark, terse_ ? "YAML aliases are not allowed in a sequence index"
                                        : "YAML aliases (*name) are not supported; write the values out");
      case YAML_SCALAR_EVENT: {
        const auto& scalar = event.data.scalar;
        if (!CheckProperties(mark, scalar.anchor, scalar.tag, error)) return false;
        const char* value = reinterpret_cast<const char*>(scalar.value);
        const bool plain = scalar.style == YAML_PLAIN_SCALAR_STYLE && scalar.tag == nullptr;
        if (plain && IsNull(value, scalar.length)) return Add(MakeNode(YamlNode::Kind::kNull, mark), error);
        YamlNode node = MakeNode(YamlNode::Kind::kScalar, mark);
        node.scalar.assign(value, scalar.length);
        node.plain = plain;
        return Add(std::move(node), error);
      }
      case YAML_SEQUENCE_START_EVENT:
        return StartCollection(YamlNode::Kind::kSequence, mark, event.data.sequence_start.anchor,
                               event.data.sequence_start.tag, error);
      case YAML_MAPPING_START_EVENT:
        return StartCollection(YamlNode::Kind::kMap, mark, event.data.mapping_start.anchor,
                               event.data.mapping_start.tag, error);
      case YAML_SEQUENCE_END_EVENT:
      case YAML_MAPPING_END_EVENT:
        stack_.pop_back();
        return true;
      default:
        return true;
    }
  }

  bool found_document() const { return documents_ > 0; }
  bool document_ended() const { return document_ended_; }

 private:
  struct Frame {
    YamlNode* node;
    std::unordered_set<std::string> keys;  // for maps: duplicate detection in O(1)
  };

  static int Line(const yaml_mark_t& mark) { return static_cast<int>(mark.line) + 1; }

  static bool Fail(TreeError* error, int line, std::string message) {
    *error = TreeError{line, std::move(message)};
    return false;
  }
  static bool Fail(TreeError* error, const yaml_mark_t& mark, std::string message) {
    return Fail(error, Line(mark), std::move(message));
  }

  static YamlNode MakeNode(YamlNode::Kind kind, const yaml_mark_t& mark) {
    YamlNode node;
    node.kind = kind;
    node.line = Line(mark);
    node.column = static_cast<int>(mark.column) + 1;
    return node;
  }

  // No anchors; no tags but the non-specific `!` (which makes a scalar a string).
  bool CheckProperties(const yaml_mark_t& mark, const yaml_char_t* anchor, const yaml_char_t* tag, TreeError* error) const {
    if (anchor != nullptr) {
      return Fail(error, mark, terse_ ? "YAML anchors are not allowed in a sequence index"
                                      : "YAML anchors (&name) are not supported; write the values out");
    }
    const bool accepted = tag != nullptr && !rules_.accepted_tag_prefix.empty() &&
                          Text(tag).rfind(rules_.accepted_tag_prefix, 0) == 0;
    if (tag != nullptr && Text(tag) != "!" && !accepted) {
      return Fail(error, mark, "explicit YAML tags (" + Text(tag) + ") are not " + (terse_ ? "allowed" : "supported"));
    }
    return true;
  }

  bool StartCollection(YamlNode::Kind kind, const yaml_mark_t& mark, const yaml_char_t* anchor, const yaml_char_t* tag,
                       TreeError* error) {
    if (!CheckProperties(mark, anchor, tag, error)) return false;
    YamlNode* node = nullptr;
    if (!Add(MakeNode(kind, mark), error, &node)) return false;
    if (static_cast<int>(stack_.size()) >= rules_.max_depth) {
      return Fail(error, mark, "YAML nested deeper than " + std::to_string(rules_.max_depth) + " levels");
    }
    stack_.push_back(Frame{node, {}});
    return true;
  }

  // Attaches a node to the collection being built and sets `*where` to where it now lives (nullptr for
  // map keys); false with `error` set on a refusal. Pointers stay valid: a parent's item vector grows only
  // after the previous child is complete.
  bool Add(YamlNode node, TreeError* error, YamlNode** where = nullptr) {
    if (++count_ > rules_.max_nodes) {
      return Fail(error, node.line, "more than " + std::to_string(rules_.max_nodes) + " YAML nodes");
    }
    YamlNode* placed = nullptr;
    if (stack_.empty()) {
      *root_ = std::move(node);
      placed = root_;
    } else if (Frame& frame = stack_.back(); frame.node->IsSequence()) {
      frame.node->items.push_back(std::move(node));
      placed = &frame.node->items.back();
    } else if (YamlNode* parent = frame.node; parent->keys.size() == parent->items.size()) {  // a key
      if (!node.IsScalar()) {
        return Fail(error, node.line, terse_          ? "map keys must be plain strings"
                                      : node.IsNull() ? "empty map key"
                                                      : "map keys must be plain strings, not collections");
      }
      if (!frame.keys.insert(node.scalar).second) return Fail(error, node.line, "duplicate key `" + node.scalar + "`");
      parent->keys.push_back(node.scalar);
      parent->key_lines.push_back(node.line);
    } else {
      if (node.IsNull()) node.line = parent->key_lines.back();
      parent->items.push_back(std::move(node));
      placed = &parent->items.back();
    }
    if (where != nullptr) *where = placed;
    return true;
  }

  const YamlRules& rules_;
  const bool terse_;
  YamlNode* root_;
  std::vector<Frame> stack_;
  size_t count_ = 0;
  int documents_ = 0;
  bool document_ended_ = false;
};

}  // namespace

Result<YamlDocument> ParseYamlText(const std::string& text_in, const std::string& name, const YamlRules& rules) {
  if (text_in.size() > rules.max_bytes) {
    const int line = 1 + static_cast<int>(std::count(text_in.begin(), text_in.begin() + rules.max_bytes, '\n'));
    return Status::InvalidInput(name + " is " + std::to_string(text_in.size()) + " bytes, more than the limit of " +
                                std::to_string(rules.max_bytes) + " bytes (the limit falls at " + At(name, line) + ")");
  }
  std::string text = text_in;
  if (Status s = Normalise(rules, name, &text); !s.ok()) return s;
  // OpenCV's FileStorage starts its files with `%YAML:1.0`, which libyaml refuses as a malformed directive
  // (yaml-cpp ignored it as an unknown one): that first line is read as a comment.
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';

  YamlDocument doc;
  doc.path = name;
  try {
    EventSource events(text);
    TreeBuilder builder(rules, &doc.root);
    TreeError error;
    for (;;) {
      const yaml_event_t* event = events.Next();
      if (event == nullptr) {
        // libyaml refuses text after a document's end (`...`) that does not start a new one with `---`.
        if (!builder.document_ended()) return events.Problem(name);
        return Refusal(rules, name, events.ProblemLine(),
                       Terse(rules) ? "more than one YAML document" : "more than one YAML document (text after the end of the first)");
      }
      if (event->type == YAML_STREAM_END_EVENT) break;
      if (!builder.Handle(*event, &error)) return Refusal(rules, name, error.line, error.message);
    }
    if (!builder.found_document()) {
      return Status::InvalidInput("no YAML document at " + At(name, 1) + " (the file is empty or holds only comments)");
    }
  } catch (const std::bad_alloc&) {
    return Status::InvalidInput("out of memory while parsing " + name);
  }
  return doc;
}

Result<YamlDocument> LoadYamlFile(const std::string& path) {
  Result<std::string> text = ReadFileCapped(path, kMaxYamlBytes);
  if (!text.ok()) return text.status();
  return ParseYamlText(*text, path);
}

}  // namespace selfcal::yaml
