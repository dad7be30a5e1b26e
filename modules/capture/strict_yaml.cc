#include "capture/strict_yaml.h"

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

namespace selfcal::capture::internal {

const YamlTree* YamlTree::Find(const std::string& key) const {
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] == key) return &items[i];
  }
  return nullptr;
}

const char* YamlTree::KindName() const {
  switch (kind) {
    case Kind::kNull:
      return "an empty value";
    case Kind::kScalar:
      return "a scalar";
    case Kind::kSequence:
      return "a sequence";
    case Kind::kMap:
      return "a map";
  }
  return "?";
}

namespace {

Status Error(const std::string& message) { return Status::Error(ExitCode::kUsage, message); }

class ParseError : public std::runtime_error {
 public:
  ParseError(int line, const std::string& message) : std::runtime_error(message), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

int Line(const YAML::Mark& mark) { return mark.line + 1; }

// Bytes the index may hold: printable ASCII, tab, line breaks, and UTF-8 multi-byte sequences (checked
// loosely: lead byte then continuation bytes). Anything else means a binary or corrupted file.
Status CheckBytes(const std::string& text, const std::string& name) {
  int line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
      continue;
    }
    if (c == '\t' || c == '\r' || (c >= 0x20 && c < 0x7F)) continue;
    const int extra = (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : -1;
    bool valid = extra > 0;
    for (int k = 1; valid && k <= extra; ++k) {
      valid = i + k < text.size() && (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    }
    if (!valid) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "0x%02X", c);
      return Error(name + ":" + std::to_string(line) + ": invalid byte " + hex + " (binary or corrupted file?)");
    }
    i += static_cast<size_t>(extra);
  }
  return Status::Ok();
}

// Flow collections ([ and {) nested deeper than the limit, before yaml-cpp scans (its scanner queues a
// token per bracket of a line). Quotes and comments are skipped.
Status PrescanFlowDepth(const std::string& text, const std::string& name) {
  int depth = 0, line = 1;
  char quote = 0, previous = '\n';
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (quote == '"') {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        quote = 0;
      }
    } else if (quote == '\'') {
      if (c == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;
      } else if (c == '\'') {
        quote = 0;
      }
    } else if (c == '#' && std::strchr(" \t\n", previous) != nullptr) {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if ((c == '"' || c == '\'') && std::strchr(" \t\n[{,:", previous) != nullptr) {
      quote = c;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxYamlDepth) {
        return Error(name + ":" + std::to_string(line) + ": YAML nested deeper than " + std::to_string(kMaxYamlDepth) +
                     " levels");
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
  explicit TreeBuilder(YamlTree* root) : root_(root) {}

  void OnDocumentStart(const YAML::Mark& mark) override {
    if (++documents_ > 1) throw ParseError(Line(mark), "more than one YAML document");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    NoAnchor(mark, anchor);
    Add(Make(YamlTree::Kind::kNull, mark));
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    throw ParseError(Line(mark), "YAML aliases are not allowed in a sequence index");
  }
  void OnAnchor(const YAML::Mark& mark, const std::string&) override {
    throw ParseError(Line(mark), "YAML anchors are not allowed in a sequence index");
  }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                const std::string& value) override {
    NoAnchor(mark, anchor);
    NoTag(mark, tag);
    YamlTree node = Make(YamlTree::Kind::kScalar, mark);
    node.scalar = value;
    node.plain = tag == "?";
    Add(std::move(node));
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    Start(YamlTree::Kind::kSequence, mark, tag, anchor);
  }
  void OnSequenceEnd() override { stack_.pop_back(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    Start(YamlTree::Kind::kMap, mark, tag, anchor);
  }
  void OnMapEnd() override { stack_.pop_back(); }

 private:
  struct Level {
    YamlTree* node;
    std::unordered_set<std::string> keys;
    bool expecting_key = true;
  };

  static YamlTree Make(YamlTree::Kind kind, const YAML::Mark& mark) {
    YamlTree node;
    node.kind = kind;
    node.line = Line(mark);
    return node;
  }
  static void NoAnchor(const YAML::Mark& mark, YAML::anchor_t anchor) {
    if (anchor != YAML::NullAnchor) throw ParseError(Line(mark), "YAML anchors are not allowed in a sequence index");
  }
  static void NoTag(const YAML::Mark& mark, const std::string& tag) {
    if (!tag.empty() && tag != "?" && tag != "!")
      throw ParseError(Line(mark), "explicit YAML tags (" + tag + ") are not allowed");
  }
  void Start(YamlTree::Kind kind, const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor) {
    NoAnchor(mark, anchor);
    NoTag(mark, tag);
    YamlTree* node = Add(Make(kind, mark));
    if (static_cast<int>(stack_.size()) >= kMaxYamlDepth) {
      throw ParseError(Line(mark), "YAML nested deeper than " + std::to_string(kMaxYamlDepth) + " levels");
    }
    stack_.push_back(Level{node, {}, true});
  }
  // A parent's item vector grows only after its previous child is complete, so pointers stay valid.
  YamlTree* Add(YamlTree node) {
    if (++count_ > kMaxYamlNodes)
      throw ParseError(node.line, "more than " + std::to_string(kMaxYamlNodes) + " YAML nodes");
    if (stack_.empty()) {
      *root_ = std::move(node);
      return root_;
    }
    Level& level = stack_.back();
    YamlTree* parent = level.node;
    if (parent->kind == YamlTree::Kind::kSequence) {
      parent->items.push_back(std::move(node));
      return &parent->items.back();
    }
    if (level.expecting_key) {
      if (node.kind != YamlTree::Kind::kScalar) throw ParseError(node.line, "map keys must be plain strings");
      if (!level.keys.insert(node.scalar).second) throw ParseError(node.line, "duplicate key `" + node.scalar + "`");
      parent->keys.push_back(node.scalar);
      level.expecting_key = false;
      return nullptr;
    }
    level.expecting_key = true;
    parent->items.push_back(std::move(node));
    return &parent->items.back();
  }

  YamlTree* root_;
  std::vector<Level> stack_;
  size_t count_ = 0;
  int documents_ = 0;
};

}  // namespace

Result<YamlTree> ParseStrictYaml(const std::string& text, const std::string& name) {
  if (Status s = CheckBytes(text, name); !s.ok()) return s;
  if (Status s = PrescanFlowDepth(text, name); !s.ok()) return s;
  YamlTree root;
  bool found = false;
  try {
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    TreeBuilder builder(&root);
    found = parser.HandleNextDocument(builder);
    if (found) parser.HandleNextDocument(builder);  // a second document throws in OnDocumentStart
  } catch (const ParseError& e) {
    return Error(name + ":" + std::to_string(e.line()) + ": " + e.what());
  } catch (const YAML::Exception& e) {
    const std::string where = e.mark.is_null() ? name : name + ":" + std::to_string(Line(e.mark));
    return Error("malformed YAML at " + where + ": " + e.msg);
  } catch (const std::bad_alloc&) {
    return Error("out of memory while parsing " + name);
  } catch (const std::exception& e) {
    return Error("cannot parse " + name + ": " + e.what());
  }
  if (!found) return Error(name + " is empty (no YAML document)");
  return root;
}

}  // namespace selfcal::capture::internal
