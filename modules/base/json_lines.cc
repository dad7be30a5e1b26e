#include "base/json_lines.h"

#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/terminal_text.h"

namespace selfcal {

namespace {

constexpr std::size_t kMaxRecordedDepth = 64;

// A key as nlohmann reads it: the raw text between the quotes with its escapes decoded.
std::string DecodeKey(std::string_view raw) {
  if (raw.find('\\') == std::string_view::npos) return std::string(raw);
  const nlohmann::json decoded = nlohmann::json::parse("\"" + std::string(raw) + "\"", nullptr, false);
  return decoded.is_string() ? decoded.get<std::string>() : std::string(raw);
}

// One pass over the text in a loop with an explicit stack (a document nested a million deep must not
// exhaust the call stack): what comes next is a value, a member of an object, or what follows a value.
class JsonScanner {
 public:
  // `lines` null: only the first repeated key is looked for.
  JsonScanner(std::string_view text, std::map<std::string, int>* lines, std::optional<JsonDuplicateKey>* duplicate)
      : text_(text), lines_(lines), duplicate_(duplicate) {}

  void Run() {
    enum class Next { kValue, kMember, kAfterValue };
    Next next = Next::kValue;
    std::string pointer;  // of the value that comes next
    while (true) {
      SkipSpace();
      if (next == Next::kValue) {
        if (at_ >= text_.size()) return;
        if (lines_ != nullptr) lines_->emplace(pointer, line_);  // unless its key's line is recorded already
        const char c = text_[at_];
        if (c != '{' && c != '[') {
          if (!Scalar()) return;
          next = Next::kAfterValue;
          continue;
        }
        ++at_;
        stack_.push_back({stack_.size() < kMaxRecordedDepth ? pointer : std::string(), c == '[', 0, {}});
        SkipSpace();
        if (At(c == '{' ? '}' : ']')) {
          ++at_;
          stack_.pop_back();
          next = Next::kAfterValue;
        } else if (c == '{') {
          next = Next::kMember;
        } else {
          pointer = Child(JsonLines::Element(pointer, 0));
        }
      } else if (next == Next::kMember) {
        std::string_view raw;
        if (!At('"') || !String(&raw)) return;
        const std::string key = DecodeKey(raw);
        pointer = Child(JsonLines::Member(stack_.back().pointer, key));
        NoteKey(key);
        // the last of repeated keys, as nlohmann keeps the last value
        if (lines_ != nullptr && stack_.size() <= kMaxRecordedDepth) (*lines_)[pointer] = line_;
        SkipSpace();
        if (!At(':')) return;
        ++at_;
        next = Next::kValue;
      } else {
        if (stack_.empty()) return;
        Frame& frame = stack_.back();
        if (At(',')) {
          ++at_;
          ++frame.index;
          if (frame.array) pointer = Child(JsonLines::Element(frame.pointer, frame.index));
          next = frame.array ? Next::kValue : Next::kMember;
        } else if (At(frame.array ? ']' : '}')) {
          ++at_;
          stack_.pop_back();
        } else {
          return;
        }
      }
    }
  }

 private:
  struct Frame {
    std::string pointer;  // empty below the recorded depth
    bool array = false;
    std::size_t index = 0;
    std::map<std::string, int> keys;  // of an object: the line of each key read so far
  };

  // Records the first key that the innermost object already holds.
  void NoteKey(const std::string& key) {
    const auto [it, added] = stack_.back().keys.emplace(key, line_);
    if (added || duplicate_->has_value()) return;
    *duplicate_ = JsonDuplicateKey{JsonLines::Member(stack_.back().pointer, key), line_, it->second};
  }

  bool At(char c) const { return at_ < text_.size() && text_[at_] == c; }

  void SkipSpace() {
    while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\t' || text_[at_] == '\n' || text_[at_] == '\r')) {
      if (text_[at_] == '\n') ++line_;
      ++at_;
    }
  }

  // Past the string that starts at the current quote; its text between the quotes in *raw.
  bool String(std::string_view* raw) {
    const std::size_t start = ++at_;
    while (at_ < text_.size() && text_[at_] != '"') {
      if (text_[at_] == '\n') return false;  // not JSON: strings hold no raw line break
      at_ += text_[at_] == '\\' ? 2 : 1;
    }
    if (at_ >= text_.size()) return false;
    *raw = text_.substr(start, at_ - start);
    ++at_;
    return true;
  }

  // Past a string, number or literal.
  bool Scalar() {
    if (At('"')) {
      std::string_view ignored;
      return String(&ignored);
    }
    const std::size_t start = at_;
    while (at_ < text_.size() && std::string_view(",]} \t\r\n").find(text_[at_]) == std::string_view::npos) ++at_;
    return at_ > start;
  }

  // The pointer of a child of the innermost container; below the recorded depth, the deepest recorded
  // container's own.
  std::string Child(std::string child) const {
    return stack_.size() > kMaxRecordedDepth ? stack_[kMaxRecordedDepth - 1].pointer : child;
  }

  std::string_view text_;
  std::map<std::string, int>* lines_;
  std::optional<JsonDuplicateKey>* duplicate_;
  std::vector<Frame> stack_;
  std::size_t at_ = 0;
  int line_ = 1;
};

}  // namespace

JsonLines::JsonLines(std::string_view text) {
  lines_[""] = FirstValueLine(text);
  JsonScanner(text, &lines_, &duplicate_).Run();
}

std::optional<JsonDuplicateKey> FindDuplicateJsonKey(std::string_view text) {
  std::optional<JsonDuplicateKey> duplicate;
  JsonScanner(text, nullptr, &duplicate).Run();
  return duplicate;
}

std::string JsonPointerName(const std::string& pointer) {
  std::string name;
  std::size_t at = 0;
  while (at < pointer.size()) {
    const std::size_t end = std::min(pointer.find('/', at + 1), pointer.size());
    std::string segment;
    for (std::size_t i = at + 1; i < end; ++i) {
      const bool escape = pointer[i] == '~' && i + 1 < end;
      segment += escape ? (pointer[i + 1] == '1' ? '/' : '~') : pointer[i];
      if (escape) ++i;
    }
    const bool index = !segment.empty() && segment.find_first_not_of("0123456789") == std::string::npos;
    name += index ? "[" + segment + "]" : (name.empty() ? "" : ".") + segment;
    at = end;
  }
  return name;
}

std::string DuplicateKeyProblem(const JsonDuplicateKey& duplicate) {
  return "`" + TerminalSafe(JsonPointerName(duplicate.pointer)) + "` is given twice (lines " +
         std::to_string(duplicate.first_line) + " and " + std::to_string(duplicate.line) +
         "): a JSON reader would keep one of them without a word; keep one";
}

int JsonLines::Line(const std::string& pointer) const {
  for (std::string p = pointer;;) {
    if (const auto it = lines_.find(p); it != lines_.end()) return it->second;
    const std::size_t slash = p.rfind('/');
    if (p.empty() || slash == std::string::npos) return lines_.at("");
    p.erase(slash);
  }
}

std::string JsonLines::Member(const std::string& parent, std::string_view key) {
  std::string pointer = parent + "/";
  for (const char c : key) {
    if (c == '~') {
      pointer += "~0";
    } else if (c == '/') {
      pointer += "~1";
    } else {
      pointer += c;
    }
  }
  return pointer;
}

std::string JsonLines::Element(const std::string& parent, std::size_t index) {
  return parent + "/" + std::to_string(index);
}

int LineOfOffset(std::string_view text, std::size_t offset) {
  const std::size_t end = std::min(offset, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
}

int FirstValueLine(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  return LineOfOffset(text, first == std::string_view::npos ? text.size() : first);
}

std::optional<JsonSyntaxError> FindJsonSyntaxError(std::string_view text) {
  try {
    const nlohmann::json parsed = nlohmann::json::parse(text);
    if (!parsed.is_discarded()) return std::nullopt;
  } catch (const nlohmann::json::parse_error& e) {
    std::string reason = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error while parsing ..."
    if (const std::size_t column = reason.find(", column "); column != std::string::npos) {
      const std::size_t colon = reason.find(": ", column);
      if (colon != std::string::npos) reason.erase(0, colon + 2);
    } else if (const std::size_t bracket = reason.find("] "); bracket != std::string::npos) {
      reason.erase(0, bracket + 2);
    }
    return JsonSyntaxError{LineOfOffset(text, e.byte == 0 ? 0 : e.byte - 1), TerminalSafe(reason)};
  } catch (const nlohmann::json::exception& e) {
    return JsonSyntaxError{1, TerminalSafe(e.what())};
  }
  return std::nullopt;
}

}  // namespace selfcal
