// A URDF's text through urdfdom, with refusals that name the file and the line (internal to the module).
//
// urdfdom answers a text it cannot take with a null model and says why only through console_bridge (and
// tinyxml, which it parses with, recurses once per nested element: 100,000 of them overflow the stack).
// ParseUrdfText therefore (1) scans the text without recursion (base/xml_scan.h: size, depth, tags closed
// and matched), (2) parses it with tinyxml, the parser urdfdom uses, for the line of a syntax error, and
// (3) hands it to urdfdom with console_bridge's output captured, naming the line of the element whose
// name urdfdom's message mentions (a link or joint), else the line of <robot>.
#pragma once

#include <memory>
#include <string>

#include "base/status.h"

namespace urdf {
class ModelInterface;
}

namespace selfcal::urdf {

inline constexpr std::size_t kMaxUrdfBytes = 16u << 20;

// urdfdom's model of the URDF `text` (`name` stands for the file in messages). Errors: kInvalidInput,
// "<name>:<line>: ...".
Result<std::shared_ptr<::urdf::ModelInterface>> ParseUrdfText(const std::string& text, const std::string& name);

// `status` ("<name>: ... joint `j` ...", a refusal of the chain or its model) with the line of the element it
// quotes by name inserted after `name` (else the line of <robot>); other statuses unchanged.
Status WithUrdfLine(const std::string& text, const std::string& name, const Status& status);

}  // namespace selfcal::urdf
