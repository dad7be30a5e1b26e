// The lines of an OpenCV FileStorage text (YAML, JSON or XML), for refusals that name `file:line`:
// cv::FileStorage keeps no source positions for its nodes, and names a line only in its parse errors
// (as "'(<line>): <reason>'" in the cv::Exception's text).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace selfcal::io {

class OpenCvLines {
 public:
  // `text` the file's contents, `top_keys` the keys of its top-level map (cv::FileNode::keys()).
  OpenCvLines(const std::string& text, const std::vector<std::string>& top_keys);

  // The line (from 1) of top-level key `key`: of all the lines whose first token is the key (YAML
  // `key:`, `"key":` or `'key':`, XML `<key>`), the first of the least indented (a nested map's key of
  // the same name is indented deeper); failing that (JSON on one line) the line of the first `"key"`;
  // for a key the text does not hold, Document().
  int Key(const std::string& key) const;

  // The line of the top-level map: the first line that holds one of its keys, or 1 when it has none.
  int Document() const { return document_; }

 private:
  int Find(const std::string& key) const;  // 0: not found

  std::vector<std::string> lines_;
  int document_ = 1;
};

// The line and reason of a cv::FileStorage parse error ("... in function '(4): Missing , between the
// elements'"), or none when the text carries no line.
struct OpenCvParseError {
  int line = 1;
  std::string reason;
};
std::optional<OpenCvParseError> ParseOpenCvError(const std::string& what);

}  // namespace selfcal::io
