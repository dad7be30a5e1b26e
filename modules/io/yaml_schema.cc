#include "io/yaml_schema.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "base/terminal_text.h"
#include "geometry/rigid3.h"

namespace selfcal::io {

namespace {

std::string FormatBound(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

// The value as written, shortened for messages; a double-quoted scalar's escapes ("\e[2J", "\0") may
// have made control characters, shown escaped (base/terminal_text.h).
std::string Shown(const yaml::YamlNode& node) {
  if (!node.IsScalar()) return node.KindName();
  std::string text = node.scalar.size() > 40 ? node.scalar.substr(0, 37) + "..." : node.scalar;
  return "`" + TerminalSafe(text) + "`";
}

std::string Where(const std::string& name, const yaml::YamlNode& node, const Problems& problems) {
  return "`" + name + "` = " + Shown(node) + " at " + problems.At(node.line);
}

// `key:` with nothing after it.
bool ReportIfEmpty(const yaml::YamlNode& node, const std::string& name, Problems* problems) {
  if (!node.IsNull()) return false;
  problems->Add("`" + name + "` at " + problems->At(node.line) + " has no value");
  return true;
}

enum class Parsed { kOk, kNotANumber, kNotFinite };

Parsed ParseNumber(const std::string& text, double* out) {
  std::string s = text;
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  std::string lower = s;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (!lower.empty() && lower[0] == '-') lower.erase(0, 1);
  if (lower == ".nan" || lower == ".inf" || lower == "nan" || lower == "inf" || lower == "infinity") {
    return Parsed::kNotFinite;
  }
  if (s.empty()) return Parsed::kNotANumber;
  // std::from_chars: locale-independent and correctly rounded, so a value written with
  // std::to_chars reads back bit-identical.
  double value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value, std::chars_format::general);
  if (ptr != s.data() + s.size()) return Parsed::kNotANumber;
  if (ec == std::errc::result_out_of_range) return Parsed::kNotFinite;
  if (ec != std::errc()) return Parsed::kNotANumber;
  if (!std::isfinite(value)) return Parsed::kNotFinite;
  *out = value;
  return Parsed::kOk;
}

double DisplayScale(KeyUnit unit) {
  switch (unit) {
    case KeyUnit::kSi: return 1.0;
    case KeyUnit::kMillimetre: return 1000.0;
    case KeyUnit::kDegree: return 180.0 / kPi;
  }
  return 1.0;
}

}  // namespace

void Problems::Add(std::string message) {
  ++count_;
  if (messages_.size() < kMaxKept) messages_.push_back(std::move(message));
}

Status Problems::ToStatus(const std::string& what) const {
  std::string text = "cannot load " + what + " from " + file_ + " (" + std::to_string(count_) +
                     (count_ == 1 ? " problem):" : " problems):");
  for (const std::string& m : messages_) text += "\n  - " + m;
  if (count_ > messages_.size()) text += "\n  ... and " + std::to_string(count_ - messages_.size()) + " more";
  return Status::Error(ErrorCode::kInvalidInput, text);
}

bool Range::Contains(double v) const {
  const bool above = min_open ? v > min : v >= min;
  const bool below = max_open ? v < max : v <= max;
  return above && below;
}

std::string Range::Describe(double scale) const {
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  const std::string lo = FormatBound(min * scale), hi = FormatBound(max * scale);
  if (has_min && has_max) return "in " + std::string(min_open ? "(" : "[") + lo + ", " + hi + (max_open ? ")" : "]");
  if (has_min) return (min_open ? "> " : ">= ") + lo;
  if (has_max) return (max_open ? "< " : "<= ") + hi;
  return "a number";
}

double ToSi(double value, KeyUnit unit) {
  switch (unit) {
    case KeyUnit::kSi: return value;
    case KeyUnit::kMillimetre: return value / 1000.0;
    case KeyUnit::kDegree: return DegToRad(value);
  }
  return value;
}

bool ReadDouble(const yaml::YamlNode& node, const std::string& name, const Range& range_si, Problems* problems,
                double* out, KeyUnit unit) {
  if (ReportIfEmpty(node, name, problems)) return false;
  if (!node.IsScalar() || !node.plain) {
    problems->Add(Where(name, node, *problems) + " is not a number (found " + node.KindName() + ")");
    return false;
  }
  double value = 0;
  switch (ParseNumber(node.scalar, &value)) {
    case Parsed::kNotANumber:
      problems->Add(Where(name, node, *problems) + " is not a number");
      return false;
    case Parsed::kNotFinite:
      problems->Add(Where(name, node, *problems) + " is not finite");
      return false;
    case Parsed::kOk: break;
  }
  const double si = ToSi(value, unit);
  if (!range_si.Contains(si)) {
    problems->Add(Where(name, node, *problems) + " is out of range: must be " + range_si.Describe(DisplayScale(unit)));
    return false;
  }
  *out = si;
  return true;
}

bool ReadInt(const yaml::YamlNode& node, const std::string& name, long long min, long long max, Problems* problems,
             long long* out) {
  if (ReportIfEmpty(node, name, problems)) return false;
  if (!node.IsScalar() || !node.plain) {
    problems->Add(Where(name, node, *problems) + " is not an integer (found " + node.KindName() + ")");
    return false;
  }
  std::string s = node.scalar;
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size()) {
    problems->Add(Where(name, node, *problems) + " is not an integer");
    return false;
  }
  if (value < min || value > max) {
    problems->Add(Where(name, node, *problems) + " is out of range: must be in [" + std::to_string(min) + ", " +
                  std::to_string(max) + "]");
    return false;
  }
  *out = value;
  return true;
}

bool ReadString(const yaml::YamlNode& node, const std::string& name, Problems* problems, std::string* out) {
  if (ReportIfEmpty(node, name, problems)) return false;
  if (!node.IsScalar()) {
    problems->Add(Where(name, node, *problems) + " must be a string (found " + node.KindName() + ")");
    return false;
  }
  *out = node.scalar;
  return true;
}

bool ReadDoubleList(const yaml::YamlNode& node, const std::string& name, int size, const Range& range_si,
                    Problems* problems, std::vector<double>* out, KeyUnit unit, std::vector<int>* lines) {
  if (ReportIfEmpty(node, name, problems)) return false;
  if (!node.IsSequence()) {
    problems->Add(Where(name, node, *problems) + " must be a sequence of numbers (found " + node.KindName() + ")");
    return false;
  }
  if (size >= 0 && static_cast<int>(node.items.size()) != size) {
    problems->Add("`" + name + "` at " + problems->At(node.line) + " has " + std::to_string(node.items.size()) +
                  " values, expected " + std::to_string(size));
    return false;
  }
  std::vector<double> values(node.items.size());
  bool ok = true;
  for (size_t i = 0; i < node.items.size(); ++i) {
    ok &= ReadDouble(node.items[i], name + "[" + std::to_string(i) + "]", range_si, problems, &values[i], unit);
  }
  if (!ok) return false;
  *out = std::move(values);
  if (lines) {
    lines->clear();
    for (const yaml::YamlNode& item : node.items) lines->push_back(item.line);
  }
  return true;
}

MapReader::MapReader(const yaml::YamlNode& node, std::string name, Problems* problems)
    : node_(&node), name_(std::move(name)), problems_(problems), line_(node.line) {
  if (!node.IsMap()) {
    const std::string what = name_.empty() ? "the document" : "`" + name_ + "`";
    problems_->Add(what + " at " + problems_->At(node.line) + " must be a map of `key: value` entries (found " +
                   node.KindName() + ")");
    node_ = nullptr;
  }
}

MapReader::~MapReader() {
  if (!finished_) Finish();
}

bool LooksLikeRadiansUnderDegrees(const std::vector<double>& values_rad) {
  constexpr double kTwoPiDeg = 2 * kPi;
  bool any = false;
  for (const double v : values_rad) {
    const double deg = RadToDeg(v);
    if (!(std::abs(deg) <= kTwoPiDeg + 1e-9)) return false;
    any |= deg != 0;
  }
  return any;
}

std::string RadiansUnderDegreesProblem(const std::string& name, const std::string& at,
                                       const std::vector<double>& values_rad, const std::string& radian_key) {
  std::string list;
  for (std::size_t i = 0; i < values_rad.size() && i < 8; ++i) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", RadToDeg(values_rad[i]));
    list += (i ? ", " : "") + std::string(text);
  }
  if (values_rad.size() > 8) list += ", ...";
  return "`" + name + "` at " + at + " holds [" + list + "]: " +
         "every value within +-6.2832 (2 pi), as joint angles in radians are" +
         ", not degrees (that would put every joint within 6.3 deg of its zero); give radians under `" + radian_key +
         "` (a pose truly that close to zero too)";
}

std::string MapReader::Path(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }

int MapReader::KeyLine(const std::string& key) const {
  if (!node_) return line_;
  for (size_t i = 0; i < node_->keys.size(); ++i) {
    if (node_->keys[i] == key) return node_->key_lines[i];
  }
  return line_;
}

const yaml::YamlNode* MapReader::Optional(const std::string& key) {
  if (std::find(allowed_.begin(), allowed_.end(), key) == allowed_.end()) allowed_.push_back(key);
  if (!node_) return nullptr;
  for (size_t i = 0; i < node_->keys.size(); ++i) {
    if (node_->keys[i] == key) return &node_->items[i];
  }
  return nullptr;
}

const yaml::YamlNode* MapReader::Required(const std::string& key) {
  const yaml::YamlNode* value = Optional(key);
  if (!value && node_) missing_.push_back("`" + key + "`");
  return value;
}

void MapReader::Disallow(const std::string& key, const std::string& reason) {
  not_suggested_.push_back(key);
  if (Optional(key)) disallowed_.emplace_back(key, reason);
}

bool MapReader::Double(const std::string& key, const Range& range, double* out) {
  const yaml::YamlNode* value = Required(key);
  return value && ReadDouble(*value, Path(key), range, problems_, out);
}

bool MapReader::OptionalDouble(const std::string& key, const Range& range, double* out) {
  const yaml::YamlNode* value = Optional(key);
  return !value || ReadDouble(*value, Path(key), range, problems_, out);
}

bool MapReader::Int(const std::string& key, long long min, long long max, long long* out) {
  const yaml::YamlNode* value = Required(key);
  return value && ReadInt(*value, Path(key), min, max, problems_, out);
}

bool MapReader::String(const std::string& key, std::string* out) {
  const yaml::YamlNode* value = Required(key);
  return value && ReadString(*value, Path(key), problems_, out);
}

bool MapReader::OptionalString(const std::string& key, std::string* out) {
  const yaml::YamlNode* value = Optional(key);
  return !value || ReadString(*value, Path(key), problems_, out);
}

bool MapReader::OptionalName(const std::string& key, std::string* out) {
  const yaml::YamlNode* value = Optional(key);
  if (!value) return true;
  if (!ReadString(*value, Path(key), problems_, out)) return false;
  if (!out->empty()) return true;
  problems_->Add("`" + Path(key) + "` at " + problems_->At(value->line) +
                 " is empty: give the name or leave the key out");
  return false;
}

const yaml::YamlNode* MapReader::FindWithUnit(const std::string& base, Unit unit, bool required, std::string* key,
                                        KeyUnit* key_unit) {
  std::vector<std::pair<std::string, KeyUnit>> variants;
  switch (unit) {
    case Unit::kNone: variants = {{base, KeyUnit::kSi}}; break;
    case Unit::kLength: variants = {{base + "_mm", KeyUnit::kMillimetre}, {base + "_m", KeyUnit::kSi}}; break;
    case Unit::kAngle: variants = {{base + "_deg", KeyUnit::kDegree}, {base + "_rad", KeyUnit::kSi}}; break;
  }
  if (unit != Unit::kNone) {
    // C4: a bare `length: 250` could be mm or m.
    Disallow(base, "the unit goes in the key: `" + variants[0].first + "` or `" + variants[1].first + "`");
  }
  const yaml::YamlNode* found = nullptr;
  for (const auto& [name, variant_unit] : variants) {
    const yaml::YamlNode* value = Optional(name);
    if (!value) continue;
    if (found) {
      problems_->Add("`" + Path(*key) + "` and `" + Path(name) + "` at " + problems_->At(KeyLine(name)) +
                     " give the same quantity twice; keep one");
      return nullptr;
    }
    found = value;
    *key = name;
    *key_unit = variant_unit;
  }
  if (!found && required && node_) {
    std::string description = "`" + variants[0].first + "`";
    if (variants.size() > 1) description += " (or `" + variants[1].first + "`)";
    missing_.push_back(description);
  }
  return found;
}

bool MapReader::Quantity(const std::string& base, Unit unit, const Range& range_si, double* out_si, bool required) {
  std::string key;
  KeyUnit key_unit = KeyUnit::kSi;
  const yaml::YamlNode* value = FindWithUnit(base, unit, required, &key, &key_unit);
  if (!value) return !required && node_;
  return ReadDouble(*value, Path(key), range_si, problems_, out_si, key_unit);
}

bool MapReader::QuantityList(const std::string& base, Unit unit, int size, const Range& range_si,
                             std::vector<double>* out_si, bool required, std::string* key_used,
                             std::vector<int>* lines) {
  std::string key;
  KeyUnit key_unit = KeyUnit::kSi;
  const yaml::YamlNode* value = FindWithUnit(base, unit, required, &key, &key_unit);
  if (!value) return !required && node_;
  if (key_used) *key_used = key;
  return ReadDoubleList(*value, Path(key), size, range_si, problems_, out_si, key_unit, lines);
}

bool MapReader::JointAngles(int size, std::vector<double>* out_rad) {
  const Range plausible = Range::Closed(DegToRad(-720), DegToRad(720));
  std::string key;
  if (!QuantityList("joints", Unit::kAngle, size, plausible, out_rad, true, &key)) return false;
  if (key != "joints_deg" || !LooksLikeRadiansUnderDegrees(*out_rad)) return true;
  problems_->Add(RadiansUnderDegreesProblem(Path(key), problems_->At(KeyLine(key)), *out_rad, "joints_rad"));
  return false;
}

void MapReader::Finish() {
  if (finished_ || !node_) {
    finished_ = true;
    return;
  }
  finished_ = true;
  for (size_t i = 0; i < node_->keys.size(); ++i) {
    const std::string& key = node_->keys[i];
    if (std::find(allowed_.begin(), allowed_.end(), key) != allowed_.end()) continue;
    std::string message = "unknown key `" + key + "`";
    if (!name_.empty()) message += " in `" + name_ + "`";
    message += " at " + problems_->At(node_->key_lines[i]);
    std::vector<std::string> candidates;
    for (const std::string& candidate : allowed_) {
      if (std::find(not_suggested_.begin(), not_suggested_.end(), candidate) == not_suggested_.end()) {
        candidates.push_back(candidate);
      }
    }
    std::string best;
    int best_distance = 1 << 30;
    for (const std::string& candidate : candidates) {
      const int d = EditDistance(key, candidate);
      if (d < best_distance) best_distance = d, best = candidate;
    }
    const int tolerance = std::max<int>(2, static_cast<int>(key.size()) / 3);
    if (!best.empty() && best_distance <= tolerance) {
      message += "; did you mean `" + best + "`?";
    } else if (!candidates.empty()) {
      message += "; allowed keys here:";
      for (const std::string& candidate : candidates) message += " `" + candidate + "`";
    }
    problems_->Add(message);
  }
  for (const auto& [key, reason] : disallowed_) {
    problems_->Add("`" + Path(key) + "` at " + problems_->At(KeyLine(key)) + " is not allowed here: " + reason);
  }
  if (!missing_.empty()) {
    std::string message = missing_.size() == 1 ? "missing required key " : "missing required keys ";
    for (size_t i = 0; i < missing_.size(); ++i) message += (i ? ", " : "") + missing_[i];
    message += (name_.empty() ? " in the document at " : " in `" + name_ + "` at ") + problems_->At(line_);
    problems_->Add(message);
  }
}

bool CheckVersion(MapReader* root, const std::string& format, int supported_major) {
  Problems* problems = root->problems();
  const yaml::YamlNode* version = root->Optional("version");
  if (!version) {
    problems->Add("missing required key `version` (of " + format + ") in the document at " + problems->At(root->line()));
    return false;
  }
  const std::string text = version->IsScalar() ? version->scalar : "";
  const size_t dot = text.find('.');
  const std::string major_text = text.substr(0, dot);
  const std::string minor_text = dot == std::string::npos ? "" : text.substr(dot + 1);
  const auto digits = [](const std::string& s) {
    return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!version->IsScalar() || !digits(major_text) || (dot != std::string::npos && !digits(minor_text))) {
    problems->Add("`version` = " + Shown(*version) + " at " + problems->At(version->line) +
                  " must be a version number like 1 or 1.2");
    return false;
  }
  if (std::stoi(major_text) != supported_major) {
    problems->Add("`version` = `" + text + "` at " + problems->At(version->line) + ": this selfcal reads " + format +
                  " version " + std::to_string(supported_major) + ".x only (a different major version changes the " +
                  "meaning of the file)");
    return false;
  }
  return true;
}

bool CheckFormatAndVersion(MapReader* root, const std::string& expected_format, int supported_major) {
  Problems* problems = root->problems();
  if (!root->ok()) return false;
  const yaml::YamlNode* format = root->Optional("format");
  if (!format) {
    problems->Add("missing required key `format` (expected `format: " + expected_format + "`) in the document at " +
                  problems->At(root->line()));
    return false;
  }
  if (!format->IsScalar() || format->scalar != expected_format) {
    problems->Add("`format` = " + Shown(*format) + " at " + problems->At(format->line) + ": expected `" +
                  expected_format + "`; is this the right file?");
    return false;
  }
  return CheckVersion(root, expected_format, supported_major);
}

}  // namespace selfcal::io
