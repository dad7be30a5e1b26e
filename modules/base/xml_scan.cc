#include "base/xml_scan.h"

#include <algorithm>
#include <cstdio>
#include <set>

namespace selfcal {
namespace {

// The length of the valid UTF-8 sequence at text[i], or 0.
size_t Utf8Length(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b = byte(i);
  if (b < 0x80) return 1;
  size_t n = 0;
  unsigned cp = 0;
  if ((b & 0xE0) == 0xC0) {
    n = 2, cp = b & 0x1Fu;
  } else if ((b & 0xF0) == 0xE0) {
    n = 3, cp = b & 0x0Fu;
  } else if ((b & 0xF8) == 0xF0) {
    n = 4, cp = b & 0x07u;
  } else {
    return 0;
  }
  if (i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3Fu);
  }
  static const unsigned kMin[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

class XmlScanner {
 public:
  XmlScanner(const std::string& text, const std::string& name, const XmlScanLimits& limits)
      : s_(text), name_(name), limits_(limits) {}

  Status Run() {
    while (i_ < s_.size()) {
      const size_t next = s_.find('<', i_);
      if (next == std::string::npos) {
        Advance(s_.size());
        break;
      }
      Advance(next);
      if (Status s = Markup(); !s.ok()) return s;
    }
    if (!open_.empty()) {
      return Fail(open_.back().line, "element <" + open_.back().name + "> is never closed");
    }
    return Status::Ok();
  }

 private:
  struct Open {
    std::string name;
    int line = 0;
    std::set<std::string> children;
  };

  // Moves to `to`, counting lines.
  void Advance(size_t to) {
    line_ += static_cast<int>(std::count(s_.begin() + static_cast<long>(i_), s_.begin() + static_cast<long>(to), '\n'));
    i_ = to;
  }

  Status Fail(int line, const std::string& what) const {
    return Status::Error(ErrorCode::kInvalidInput, name_ + ":" + std::to_string(line) + ": " + what);
  }

  // Skips from i_ past `end`, or fails with `unterminated`.
  Status SkipPast(const char* end, const std::string& unterminated) {
    const int start = line_;
    const size_t at = s_.find(end, i_);
    if (at == std::string::npos) return Fail(start, unterminated + " is never closed");
    Advance(at + std::char_traits<char>::length(end));
    return Status::Ok();
  }

  // The end of the tag starting at i_ (the index of its '>'), quotes and a DOCTYPE's [ ] subset honoured;
  // npos when the text ends first.
  size_t TagEnd() const {
    char quote = 0;
    int brackets = 0;
    for (size_t k = i_ + 1; k < s_.size(); ++k) {
      const char c = s_[k];
      if (quote != 0) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '[') {
        ++brackets;
      } else if (c == ']') {
        brackets = std::max(0, brackets - 1);
      } else if (c == '>' && brackets == 0) {
        return k;
      }
    }
    return std::string::npos;
  }

  std::string NameAt(size_t from) const {
    size_t end = from;
    const auto ends_name = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '/' || c == '>'; };
    while (end < s_.size() && !ends_name(s_[end])) ++end;
    return s_.substr(from, std::min<size_t>(end - from, 80));
  }

  Status Markup() {
    if (s_.compare(i_, 4, "<!--") == 0) return SkipPast("-->", "a comment");
    if (s_.compare(i_, 9, "<![CDATA[") == 0) return SkipPast("]]>", "a CDATA section");
    if (s_.compare(i_, 2, "<?") == 0) return SkipPast("?>", "a declaration <?...?>");
    const int start = line_;
    const size_t end = TagEnd();
    if (end == std::string::npos) return Fail(start, "unterminated tag `" + NameAt(i_) + "`: no `>` before the end of the file");
    if (s_.compare(i_, 2, "<!") == 0) {  // DOCTYPE and other declarations
      Advance(end + 1);
      return Status::Ok();
    }
    if (s_.compare(i_, 2, "</") == 0) {
      const std::string name = NameAt(i_ + 2);
      Advance(end + 1);
      if (open_.empty()) return Fail(start, "closing tag </" + name + "> without an open element");
      if (open_.back().name != name) {
        return Fail(start, "closing tag </" + name + "> does not match <" + open_.back().name + "> (line " +
                               std::to_string(open_.back().line) + ")");
      }
      open_.pop_back();
      return Status::Ok();
    }
    const std::string name = NameAt(i_ + 1);
    const bool self_closing = s_[end - 1] == '/';
    Advance(end + 1);
    if (!open_.empty() && limits_.refuse_repeated_siblings &&
        std::find(limits_.repeatable.begin(), limits_.repeatable.end(), name) == limits_.repeatable.end() &&
        !open_.back().children.insert(name).second) {
      return Fail(start, "element <" + name + "> appears twice in <" + open_.back().name + "> (line " +
                             std::to_string(open_.back().line) + "); give each key once");
    }
    if (self_closing) return Status::Ok();
    if (static_cast<int>(open_.size()) >= limits_.max_depth) {
      return Fail(start, "elements nested deeper than " + std::to_string(limits_.max_depth) +
                             " levels, the limit for " + limits_.kind);
    }
    open_.push_back(Open{name, start, {}});
    return Status::Ok();
  }

  const std::string& s_;
  const std::string& name_;
  const XmlScanLimits& limits_;
  size_t i_ = 0;
  int line_ = 1;
  std::vector<Open> open_;
};

}  // namespace

int FirstInvalidUtf8Line(const std::string& text) {
  int line = 1;
  for (size_t i = 0; i < text.size();) {
    const size_t n = Utf8Length(text, i);
    if (n == 0) return line;
    if (text[i] == '\n') ++line;
    i += n;
  }
  return 0;
}

namespace {
int LineAt(const std::string& text, std::size_t at) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}
}  // namespace

Status ScanXml(const std::string& text, const std::string& name, const XmlScanLimits& limits) {
  if (text.size() > limits.max_bytes) {
    return Status::Error(ErrorCode::kInvalidInput, name + " is " + std::to_string(text.size()) +
                                                       " bytes, more than the limit of " +
                                                       std::to_string(limits.max_bytes) + " bytes for " + limits.kind);
  }
  // XML 1.0 allows no control character but tab, newline and carriage return (tinyxml stops at a NUL).
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') {
      const int line = LineAt(text, i);
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", c);
      return Status::Error(ErrorCode::kInvalidInput, name + ":" + std::to_string(line) + ": control character " + hex +
                                                         " (XML allows none but tab and line ends in " + limits.kind +
                                                         ")");
    }
  }
  // The XML declaration may only open the document (after a byte order mark at most).
  const std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  for (std::size_t at = text.find("<?xml"); at != std::string::npos; at = text.find("<?xml", at + 1)) {
    const char next = at + 5 < text.size() ? text[at + 5] : '\0';
    if (at == start || (next != ' ' && next != '\t' && next != '\r' && next != '\n')) continue;
    const int line = LineAt(text, at);
    return Status::Error(ErrorCode::kInvalidInput, name + ":" + std::to_string(line) +
                                                       ": an XML declaration <?xml ...?> that does not open the file "
                                                       "(it may only be its first text)");
  }
  if (limits.require_utf8) {
    if (const int line = FirstInvalidUtf8Line(text); line > 0) {
      return Status::Error(ErrorCode::kInvalidInput,
                           name + ":" + std::to_string(line) + ": invalid UTF-8 (" + limits.kind + " must be UTF-8)");
    }
  }
  return XmlScanner(text, name, limits).Run();
}

}  // namespace selfcal
