// The lines of a JSON document's values, for refusals that name `file:line` (nlohmann::json, the JSON
// library every module uses, keeps no source positions). JsonLines scans the text once and records, for
// every value, the line where it starts, under its JSON pointer (RFC 6901: "" the document, "/camera/fx_px",
// "/inputs/2/name"); a readers' message then names the line of the key it complains about.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace selfcal {

// A key an object of a JSON text holds twice. nlohmann::json keeps the last value without a word, so a
// reader that takes the text as it is would act on one of two values the file gives; readers refuse it.
struct JsonDuplicateKey {
  std::string pointer;  // of the repeated member ("/camera/fx_px")
  int line = 1;         // of its second occurrence
  int first_line = 1;   // of its first
};

class JsonLines {
 public:
  // Indexes `text`, which should be JSON (a reader indexes what nlohmann parsed). Text that is not stops
  // the scan where it goes wrong: what was read up to there keeps its lines, the rest falls back to the
  // deepest ancestor recorded (at least the document, line 1). Values nested deeper than 64 levels are
  // recorded under their 64th ancestor.
  explicit JsonLines(std::string_view text);

  // The line (from 1) of the value at `pointer`: for an object member the line of its key, for an array
  // element or the document the line of its first character. A pointer the document does not hold (a
  // missing key) gives the line of its deepest ancestor that it holds: a missing key is named at the line
  // of the object that lacks it.
  int Line(const std::string& pointer) const;

  // The first key repeated inside one object, in text order (scanned to any depth), or none.
  const std::optional<JsonDuplicateKey>& duplicate() const { return duplicate_; }

  // The JSON pointer of member `key` of the value at `parent` (`key` escaped: "~" as "~0", "/" as "~1").
  static std::string Member(const std::string& parent, std::string_view key);
  // The JSON pointer of element `index` of the array at `parent`.
  static std::string Element(const std::string& parent, std::size_t index);

 private:
  std::map<std::string, int> lines_;
  std::optional<JsonDuplicateKey> duplicate_;
};

// The first repeated key of `text` (as JsonLines::duplicate(), without indexing the lines of every value:
// for the many small records of a journal).
std::optional<JsonDuplicateKey> FindDuplicateJsonKey(std::string_view text);

// A JSON pointer as messages show a value: "/camera/fx_px" -> "camera.fx_px", "/inputs/2/name" ->
// "inputs[2].name" (a segment of digits is an array index), "" -> "" (the document).
std::string JsonPointerName(const std::string& pointer);

// "`camera.fx_px` is given twice (lines 4 and 9); keep one": the words of every reader's refusal.
std::string DuplicateKeyProblem(const JsonDuplicateKey& duplicate);

// The line (from 1) of byte `offset` of `text` (1 + the newlines before it; past the end: the last line).
// For nlohmann's parse_error::byte, which counts from 1: pass byte - 1.
int LineOfOffset(std::string_view text, std::size_t offset);

// The line (from 1) of the first character that is not JSON white space (line 1 for an empty text): where
// a document that is not the expected kind of value starts.
int FirstValueLine(std::string_view text);

// Why a text is not JSON: the line where nlohmann stopped reading and its reason, without the exception's
// "[json.exception.parse_error.101] parse error at line 3, column 5:" prefix and terminal-safe (its
// "last read: '...'" quotes the input).
struct JsonSyntaxError {
  int line = 1;
  std::string reason;
};

// The syntax error of `text`, or none when it is JSON (a reader calls it after nlohmann refused the text).
std::optional<JsonSyntaxError> FindJsonSyntaxError(std::string_view text);

}  // namespace selfcal
