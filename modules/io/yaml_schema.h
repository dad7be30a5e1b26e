// Checking a yaml::YamlNode tree (yaml/yaml_reader.h) against a schema, collecting every problem of a file so
// that they are reported together (C1-C3). Messages name the file, the line, the dotted key path and the value:
//
//   unknown key `max_velocty` at robot.yaml:12; did you mean `max_velocity`?
//   missing required keys `fx_px`, `cx_px` in `camera` at obs.yaml:5
//   `camera.fx_px` = `-3` at obs.yaml:7 is out of range: must be > 0 and <= 1e+06
//   `poses[2].joints_deg[1]` = `.nan` at obs.yaml:30 is not finite
//
// Numbers are plain (unquoted) YAML scalars in decimal notation ("12", "-0.5", "1.5e-3"); quoted
// strings, hexadecimal and YAML 1.1 forms are refused, `.nan` / `.inf` are refused as non-finite.
// Quantities carry their unit in the key: `<name>_mm` or `<name>_m` for lengths, `<name>_deg` or
// `<name>_rad` for angles, exactly one of the pair; values come back in SI (m, rad).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "base/closest_name.h"
#include "base/status.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

// Every problem found in one file, in the order found.
class Problems {
 public:
  explicit Problems(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }
  // "FILE:LINE".
  std::string At(int line) const { return file_ + ":" + std::to_string(line); }
  // Keeps the first kMaxKept messages and counts the rest (a garbage file must not fill memory).
  void Add(std::string message);
  bool empty() const { return count_ == 0; }
  size_t size() const { return count_; }
  const std::vector<std::string>& messages() const { return messages_; }
  // ErrorCode::kInvalidInput: "cannot load <what> from FILE (N problems):" then one problem per line.
  Status ToStatus(const std::string& what) const;

  static constexpr size_t kMaxKept = 100;

 private:
  std::string file_;
  std::vector<std::string> messages_;
  size_t count_ = 0;
};

// An interval of acceptable values, in SI units.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  // min itself excluded
  bool max_open = false;

  static Range Closed(double lo, double hi) { return Range{lo, hi, false, false}; }
  static Range Positive(double hi) { return Range{0.0, hi, true, false}; }  // (0, hi]
  bool Contains(double v) const;
  // "in [a, b]" or "> a and <= b", with the bounds multiplied by `scale` (SI to the key's unit).
  std::string Describe(double scale = 1.0) const;
};

// What a quantity may be written in: Unit::kLength is `_mm` or `_m`, Unit::kAngle `_deg` or `_rad`.
enum class Unit { kNone, kLength, kAngle };
// The unit of one key's values. Conversions are v / 1000 and DegToRad(v), exactly as in code, so that
// "40 mm" is the double 0.04.
enum class KeyUnit { kSi, kMillimetre, kDegree };
double ToSi(double value, KeyUnit unit);

// Node-level reads: `name` is the dotted key path used in messages. Each records one problem and returns
// false when the node is of the wrong type, not finite or out of range. The value is converted from
// `unit` to SI before the range check (the message shows the range in `unit`).
bool ReadDouble(const yaml::YamlNode& node, const std::string& name, const Range& range_si, Problems* problems,
                double* out, KeyUnit unit = KeyUnit::kSi);
bool ReadInt(const yaml::YamlNode& node, const std::string& name, long long min, long long max, Problems* problems,
             long long* out);
bool ReadString(const yaml::YamlNode& node, const std::string& name, Problems* problems, std::string* out);
// A sequence of numbers; `size` < 0 accepts any length. Line of every element in `lines` if given.
bool ReadDoubleList(const yaml::YamlNode& node, const std::string& name, int size, const Range& range_si,
                    Problems* problems, std::vector<double>* out, KeyUnit unit = KeyUnit::kSi,
                    std::vector<int>* lines = nullptr);

// Radians typed under a degree key (../shared/RELIABILITY.md C4): joint angles read from `joints_deg` or
// `poses_deg` (`values_rad`, converted) whose every value, in degrees, lies within +-2 pi (6.2832), where
// every joint angle written in radians lies, and not all zero. In degrees such values put every joint
// within 6.3 deg of its zero; a real pose that close is given under the radian key instead.
bool LooksLikeRadiansUnderDegrees(const std::vector<double>& values_rad);
// The refusal of such values: "`<name>` at <at> holds [0.58, 0.34, ...]: every value within +-6.2832, as
// radians are: ...".
std::string RadiansUnderDegreesProblem(const std::string& name, const std::string& at,
                                       const std::vector<double>& values_rad, const std::string& radian_key);

// EditDistance (Levenshtein with adjacent transpositions) is base/closest_name.h's.

// Reads the keys of one map. Every key looked up through the reader is allowed; Finish() (or the
// destructor) reports the keys nobody asked for, with a did-you-mean suggestion, and every missing
// required key of the map in one message.
class MapReader {
 public:
  // `name` is the map's dotted path ("" for the document root). A node that is not a map is reported
  // once and every read then fails without further messages.
  MapReader(const yaml::YamlNode& node, std::string name, Problems* problems);
  ~MapReader();
  MapReader(const MapReader&) = delete;
  MapReader& operator=(const MapReader&) = delete;

  bool ok() const { return node_ != nullptr; }
  int line() const { return line_; }
  Problems* problems() const { return problems_; }
  // Dotted path of a key of this map: "camera.fx_px".
  std::string Path(const std::string& key) const;
  int KeyLine(const std::string& key) const;

  // Marks the key allowed and returns its value, or nullptr when absent (Required also records it
  // as missing).
  const yaml::YamlNode* Optional(const std::string& key);
  const yaml::YamlNode* Required(const std::string& key);
  // The key is known but not allowed in this context: reported with the reason if present.
  void Disallow(const std::string& key, const std::string& reason);
  // Records a missing requirement described in words (e.g. "`robot` or `robot_file`").
  void AddMissing(const std::string& description) { missing_.push_back(description); }

  // Typed reads; the Optional forms leave *out unchanged when the key is absent.
  bool Double(const std::string& key, const Range& range, double* out);
  bool OptionalDouble(const std::string& key, const Range& range, double* out);
  bool Int(const std::string& key, long long min, long long max, long long* out);
  bool String(const std::string& key, std::string* out);
  bool OptionalString(const std::string& key, std::string* out);
  // An optional name (e.g. `robot`): when the key is given, its string must not be empty.
  bool OptionalName(const std::string& key, std::string* out);

  // A pose's joint angles, required: `joints_deg` or `joints_rad`, `size` values (any if < 0) in
  // [-720, 720] deg, radians typed under `joints_deg` refused (LooksLikeRadiansUnderDegrees); in radians.
  bool JointAngles(int size, std::vector<double>* out_rad);

  // A quantity with a unit suffix, exactly one of `<base>_mm`/`<base>_m` or `<base>_deg`/`<base>_rad`
  // (Unit::kNone: just `<base>`); returns SI.
  bool Quantity(const std::string& base, Unit unit, const Range& range_si, double* out_si, bool required = true);
  // The same for a list of `size` numbers (any length if size < 0). `key_used` receives the key that
  // was present, `lines` the line of every element.
  bool QuantityList(const std::string& base, Unit unit, int size, const Range& range_si, std::vector<double>* out_si,
                    bool required = true, std::string* key_used = nullptr, std::vector<int>* lines = nullptr);

  // Reports unknown keys and missing required keys (once).
  void Finish();
  // Reports nothing more: for a map whose reading stopped at a fatal problem (wrong format, version).
  void Abandon() { finished_ = true; }

 private:
  // Finds which unit variant of `base` is present; records a problem if several are.
  const yaml::YamlNode* FindWithUnit(const std::string& base, Unit unit, bool required, std::string* key, KeyUnit* key_unit);

  const yaml::YamlNode* node_;
  std::string name_;
  Problems* problems_;
  int line_ = 0;
  std::vector<std::string> allowed_;
  std::vector<std::string> missing_;
  std::vector<std::pair<std::string, std::string>> disallowed_;  // present but not allowed, with why
  std::vector<std::string> not_suggested_;                         // known but never suggested
  bool finished_ = false;
};

// Reads the required `format` and `version` keys. Returns false (with the one problem recorded) when
// the format is not `expected_format` or the major version is not `supported_major` (P8); then the
// caller should stop reading. Versions are "N" or "N.M"; minor versions only add optional keys.
bool CheckFormatAndVersion(MapReader* root, const std::string& expected_format, int supported_major);
// Only the `version` key, for documents whose format is already known.
bool CheckVersion(MapReader* root, const std::string& format, int supported_major);

}  // namespace selfcal::io
