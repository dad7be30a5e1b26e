// Formatting helpers for the YAML files selfcal writes. Numbers are written with the shortest decimal
// form that reads back to the same double (std::to_chars), so a written file loads bit-identical; an
// exponent always comes with a decimal point ("1.0e-05") so YAML 1.1 readers (PyYAML) see a float too.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace selfcal::io {

// Shortest round-trip decimal; ".nan", ".inf", "-.inf" for non-finite values (writers refuse those first).
std::string YamlNumber(double value);
// "[a, b, c]".
std::string YamlNumberList(const std::vector<double>& values);
std::string YamlNumberList(const Eigen::VectorXd& values);
// A double-quoted YAML string with escapes for quote, backslash and control characters.
std::string YamlQuoted(const std::string& text);

}  // namespace selfcal::io
