#include "app/cli_numbers.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace selfcal::app {

std::string CheckIntegerText(std::string& value) {
  const bool negative = !value.empty() && value[0] == '-';
  const std::size_t start = !value.empty() && (value[0] == '-' || value[0] == '+') ? 1 : 0;
  const std::string digits = value.substr(start);
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) {
    return value + " is not a whole number in decimal digits";
  }
  if (negative && digits.find_first_not_of('0') != std::string::npos) {
    return value + " is negative: a count, size, index or seed is 0 or more";
  }
  std::uint64_t parsed = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), parsed);
  if (error != std::errc() || end != digits.data() + digits.size()) {
    return value + " is larger than the largest integer an option takes (18446744073709551615)";
  }
  value = std::to_string(parsed);  // "010" is ten, not CLI11's octal eight
  return "";
}

std::string CheckFloatText(const std::string& value) {
  char* end = nullptr;
  const double parsed = std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size()) return value + " is not a number";
  if (!std::isfinite(parsed)) return value + " is not a finite number";
  return "";
}

void CheckNumbersStrictly(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    // The type before the validators' descriptions ("UINT:NONNEGATIVE"); first of the option's
    // validators (transform), so that a Range check reads the value as decimal and never sees NaN.
    const std::string full = option->get_type_name();
    const std::string type = full.substr(0, full.find(':'));
    if (type == "INT" || type == "UINT") {
      option->transform(CLI::Validator([](std::string& value) { return CheckIntegerText(value); }, ""));
    } else if (type == "FLOAT") {
      option->transform(CLI::Validator([](std::string& value) { return CheckFloatText(value); }, ""));
    }
  }
  for (CLI::App* sub : app.get_subcommands({})) CheckNumbersStrictly(*sub);
}

}  // namespace selfcal::app
