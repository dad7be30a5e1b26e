#include "urdf/urdf_parse.h"

#include <algorithm>
#include <exception>
#include <mutex>
#include <vector>

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include "base/terminal_text.h"
#include "base/xml_scan.h"
#include "urdf/urdf_values.h"

namespace selfcal::urdf {
namespace {

// Collects what urdfdom logs (errors and warnings) instead of letting it print to stderr.
class Capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
  }
  std::vector<std::string> messages;
};

int LineAt(const std::string& text, size_t at) {
  int line = 1;
  for (size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

// The names a message quotes: between [ ], ` `, ' ' or " ".
std::vector<std::string> QuotedNames(const std::string& message) {
  std::vector<std::string> names;
  for (const auto& [open, close] : {std::pair<char, char>{'[', ']'}, {'`', '`'}, {'\'', '\''}, {'"', '"'}}) {
    for (size_t a = message.find(open); a != std::string::npos; a = message.find(open, a + 1)) {
      const size_t b = message.find(close, a + 1);
      if (b == std::string::npos) break;
      if (b > a + 1) names.push_back(message.substr(a + 1, b - a - 1));
      a = b;
    }
  }
  return names;
}

// "<line>: ... (<tag name="x">)" of the first element whose name="x" attribute a message quotes, else the
// line of <robot>.
std::string Where(const std::string& text, const std::vector<std::string>& messages) {
  for (const std::string& message : messages) {
    for (const std::string& name : QuotedNames(message)) {
      for (const char quote : {'"', '\''}) {
        const size_t at = text.find("name=" + std::string(1, quote) + name + quote);
        if (at == std::string::npos) continue;
        const size_t tag = text.rfind('<', at);
        std::string element = "element";
        if (tag != std::string::npos) {
          const size_t end = text.find_first_of(" \t\r\n/>", tag + 1);
          element = text.substr(tag + 1, std::min(end, at) - tag - 1);
        }
        return std::to_string(LineAt(text, at)) + ": the <" + TerminalSafe(element) + "> named `" +
               TerminalSafe(name) + "`";
      }
    }
  }
  const size_t robot = text.find("<robot");
  return std::to_string(LineAt(text, robot == std::string::npos ? 0 : robot)) + ": the <robot> element";
}

std::mutex& ConsoleMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

Status WithUrdfLine(const std::string& text, const std::string& name, const Status& status) {
  const std::string& message = status.message();
  const std::string prefix = name + ": ";
  if (status.ok() || message.rfind(prefix, 0) != 0) return status;
  std::string where = Where(text, {message.substr(prefix.size())});
  where = where.substr(0, where.find(':'));  // the line only: the message names the element itself
  return Status::Error(status.code(), name + ":" + where + ": " + message.substr(prefix.size()));
}

Result<std::shared_ptr<::urdf::ModelInterface>> ParseUrdfText(const std::string& text, const std::string& name) {
  XmlScanLimits limits;
  limits.kind = "a URDF";
  limits.max_bytes = kMaxUrdfBytes;
  limits.require_utf8 = true;  // XML that declares no other encoding is UTF-8; tinyxml would take any bytes
  if (Status s = ScanXml(text, name, limits); !s.ok()) return s;
  TiXmlDocument xml;
  xml.Parse(text.c_str());
  if (xml.Error()) {
    return Status::Error(ErrorCode::kInvalidInput, name + ":" + std::to_string(std::max(1, xml.ErrorRow())) +
                                                       ": not well-formed XML (tinyxml: " + xml.ErrorDesc() + ")");
  }
  if (Status s = CheckUrdfValues(xml, name); !s.ok()) return s;
  Capture capture;
  ::urdf::ModelInterfaceSharedPtr model;
  {
    // console_bridge's handler is one per process.
    const std::lock_guard<std::mutex> lock(ConsoleMutex());
    console_bridge::useOutputHandler(&capture);
    try {
      model = ::urdf::parseURDF(text);
    } catch (const std::exception& e) {
      capture.messages.push_back(e.what());
      model.reset();
    }
    console_bridge::restorePreviousOutputHandler();
  }
  if (model) return model;
  std::string said;
  for (const std::string& m : capture.messages) said += (said.empty() ? "" : "; ") + TerminalSafe(m);
  if (said.empty()) said = "no reason given";
  return Status::Error(ErrorCode::kInvalidInput,
                       name + ":" + Where(text, capture.messages) + ": urdfdom could not read the URDF: " + said);
}

}  // namespace selfcal::urdf
