#include "urdf/urdf_values.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <vector>

#include <tinyxml.h>

#include "base/terminal_text.h"

namespace selfcal::urdf {
namespace {

// The numbers of an attribute such as xyz="0 0 1"; false when one does not parse (urdfdom's to refuse).
bool Numbers(const char* text, std::vector<double>* out) {
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') return false;
    out->push_back(errno == ERANGE && std::abs(v) >= 1.0 ? HUGE_VAL : v);
  }
  return true;
}

class Checker {
 public:
  explicit Checker(std::string name) : name_(std::move(name)) {}

  void Joint(const TiXmlElement& joint) {
    const char* joint_name = joint.Attribute("name");
    what_ = "the <joint> named `" + TerminalSafe(joint_name ? joint_name : "") + "`";
    static const std::set<std::string> kKnown = {"origin", "parent",  "child", "axis", "calibration",
                                                 "dynamics", "limit", "mimic", "safety_controller"};
    std::set<std::string> seen;
    for (const TiXmlElement* e = joint.FirstChildElement(); e; e = e->NextSiblingElement()) {
      if (kKnown.count(e->ValueStr()) == 0) {
        Add(*e, "<" + TerminalSafe(e->ValueStr()) + "> is not an element of a joint (a joint's elements: <origin>, "
                "<parent>, <child>, <axis>, <limit>, <dynamics>, <calibration>, <mimic>, <safety_controller>)");
      } else if (!seen.insert(e->ValueStr()).second) {
        Add(*e, "<" + e->ValueStr() + "> is given twice in a joint (urdfdom would take the first without a word); "
                "keep one");
      }
    }
    if (const TiXmlElement* axis = joint.FirstChildElement("axis")) Values(*axis, "xyz", kMaxUrdfAxisComponent, "");
    const char* type = joint.Attribute("type");
    if (type && std::string(type) == "revolute") {
      const TiXmlElement* limit = joint.FirstChildElement("limit");
      for (const char* bound : {"lower", "upper"}) {
        if (!limit || !limit->Attribute(bound)) {
          Add(limit ? *limit : joint, "a revolute joint needs `" + std::string(bound) +
                                          "=` in its <limit> (urdfdom would take 0 rad without a word)");
        }
      }
    }
  }

  void Origin(const TiXmlElement& origin) {
    what_ = "an <origin>";
    Values(origin, "xyz", kMaxUrdfLengthM, " m");
    Values(origin, "rpy", kMaxUrdfAngleRad, " rad");
  }

  const std::string& problems() const { return problems_; }

 private:
  void Values(const TiXmlElement& e, const char* attribute, double limit, const std::string& unit) {
    const char* text = e.Attribute(attribute);
    std::vector<double> values;
    if (!text || !Numbers(text, &values)) return;
    for (double v : values) {
      if (std::isfinite(v) && std::abs(v) <= limit) continue;
      std::ostringstream out;
      out << "<" << e.ValueStr() << " " << attribute << "=\"" << TerminalSafe(text) << "\">: " << v << unit
          << " is beyond the limit of " << limit << unit << " of a URDF";
      Add(e, out.str());
      return;
    }
  }

  void Add(const TiXmlElement& at, const std::string& message) {
    problems_ += name_ + ":" + std::to_string(at.Row()) + ": " + what_ + ": " + message + "\n";
  }

  std::string name_, what_, problems_;
};

// Every <origin>; the joints of <robot> only (a <transmission> names joints with other elements).
void Walk(const TiXmlElement& e, bool in_robot, Checker* checker) {
  if (in_robot && e.ValueStr() == "joint") checker->Joint(e);
  if (e.ValueStr() == "origin") checker->Origin(e);
  for (const TiXmlElement* child = e.FirstChildElement(); child; child = child->NextSiblingElement()) {
    Walk(*child, &e == e.GetDocument()->RootElement(), checker);
  }
}

}  // namespace

Status CheckUrdfValues(const TiXmlDocument& xml, const std::string& name) {
  const TiXmlElement* robot = xml.RootElement();
  if (!robot) return Status::Ok();
  Checker checker(name);
  Walk(*robot, false, &checker);
  std::string problems = checker.problems();
  if (problems.empty()) return Status::Ok();
  problems.pop_back();
  return Status::Error(ErrorCode::kInvalidInput, problems);
}

}  // namespace selfcal::urdf
