#include "simulation/sim_run_settings.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/terminal_text.h"
#include "session/json_fields.h"

namespace selfcal::simulation {

namespace {

using nlohmann::json;
using session::JsonFields;
using session::JsonPath;
using session::JsonTypeName;

// A range's bound as messages show it ("0", "10", "0.5").
std::string Number(double x) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", x);
  return text;
}

// "must be in [lo, hi] (found v)" after a value read but out of range.
void AddOutOfRange(const JsonPath& at, const std::string& lo, const std::string& hi, const json& found,
                   JsonFields* fields) {
  fields->Add(at, "`" + at.name + "` must be in [" + lo + ", " + hi + "] (found " + found.dump() + ")");
}

// The member `key` of the object at `path` as a finite number in [lo, hi]; false after a problem.
bool GetDoubleIn(const json& object, const JsonPath& path, const std::string& key, double lo, double hi,
                 JsonFields* fields, double* out) {
  if (!fields->GetDouble(object, path, key, out)) return false;
  if (*out >= lo && *out <= hi) return true;
  AddOutOfRange(path.Member(key), Number(lo), Number(hi), *out, fields);
  return false;
}

// "seed": any unsigned 64-bit integer.
bool GetSeed(const json& object, JsonFields* fields, uint64_t* out) {
  const json* value = fields->Get(object, {}, "seed");
  if (value == nullptr) return false;
  if (!value->is_number_unsigned()) {
    const std::string found = value->is_number_integer() ? value->dump() : JsonTypeName(*value);
    fields->Add(JsonPath{}.Member("seed"),
                "`seed` must be an integer in [0, 18446744073709551615] (found " + found + ")");
    return false;
  }
  *out = value->get<uint64_t>();
  return true;
}

// A fault list of `faults` (at `path`): an array of 0-based call counts into *out.
void GetCallCounts(const json& faults, const JsonPath& path, const std::string& key, JsonFields* fields,
                   std::set<int>* out) {
  const json* list = fields->GetArray(faults, path, key);
  if (list == nullptr) return;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& k = (*list)[i];
    if (k.is_number_unsigned() && k.get<uint64_t>() <= uint64_t{INT32_MAX}) {
      out->insert(static_cast<int>(k.get<uint64_t>()));
      continue;
    }
    const JsonPath at = path.Member(key).Element(i);
    const std::string found = k.is_number_integer() ? k.dump() : JsonTypeName(k);
    fields->Add(at, "`" + at.name + "` must be a call count, an integer in [0, 2147483647] (found " + found + ")");
  }
}

// "faults": the simulated robot's injected faults, every key known.
void ParseFaults(const json& run, JsonFields* fields, robot::SimulatedRobotFaults* faults) {
  const json* f = fields->Get(run, {}, "faults");
  if (f == nullptr) return;
  const JsonPath at = JsonPath{}.Member("faults");
  if (!f->is_object()) {
    fields->Add(at, "`faults` must be an object (found " + JsonTypeName(*f) + ")");
    return;
  }
  const std::pair<const char*, std::set<int>*> lists[] = {
      {"reject_moves", &faults->reject_moves},       {"protective_stop_moves", &faults->protective_stop_moves},
      {"hang_moves", &faults->hang_moves},           {"disconnect_moves", &faults->disconnect_moves},
      {"jog_after_moves", &faults->jog_after_moves}, {"slow_settle_moves", &faults->slow_settle_moves},
      {"stale_reads", &faults->stale_reads},         {"nan_reads", &faults->nan_reads},
      {"short_reads", &faults->short_reads}};
  std::vector<std::string> known = {"jog_delay_s", "never_settle_moves"};
  for (const auto& [key, set] : lists) {
    GetCallCounts(*f, at, key, fields, set);
    known.push_back(key);
  }
  fields->CheckKnown(*f, at, known);
  // Written only when not the default (docs/session-format.md).
  if (f->contains("never_settle_moves")) GetCallCounts(*f, at, "never_settle_moves", fields, &faults->never_settle_moves);
  if (f->contains("jog_delay_s")) GetDoubleIn(*f, at, "jog_delay_s", 0, 10, fields, &faults->jog_delay_s);
}

// The member `key` as a string, one of `allowed`; false after a problem naming it.
bool GetStringOf(const json& run, const std::string& key, const std::vector<std::string>& allowed, JsonFields* fields,
                 std::string* out) {
  if (!fields->GetString(run, {}, key, out)) return false;
  if (std::find(allowed.begin(), allowed.end(), *out) != allowed.end()) return true;
  std::string list;
  for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fields->Add(JsonPath{}.Member(key), "`" + key + "` must be one of " + list + " (found \"" + TerminalSafe(*out) + "\")");
  return false;
}

// What every reader of run.json checks besides the simulated cell's settings: the format and version, the
// backends, the address and device, the velocity scaling in `selfcal run`'s range, no unknown key.
void ReadRunHeader(const json& run, JsonFields* fields, RunBackends* backends) {
  std::string format;
  if (fields->GetString(run, {}, "format", &format) && format != "selfcal-run") {
    fields->Add(JsonPath{}.Member("format"), "`format` must be \"selfcal-run\" (found \"" + TerminalSafe(format) + "\")");
  }
  int version = 0;
  if (fields->GetInt(run, {}, "version", &version) && version != 1) {
    fields->Add(JsonPath{}.Member("version"), "`version` must be 1 (found " + std::to_string(version) + ")");
  }
  GetStringOf(run, "robot", {"sim", "network", "manual", "ur", "fanuc"}, fields, &backends->robot);
  GetStringOf(run, "camera", {"sim", "v4l2", "aravis"}, fields, &backends->camera);
  std::string text;
  fields->GetString(run, {}, "address", &text);
  fields->GetString(run, {}, "device", &text);
  double scaling = 0;
  GetDoubleIn(run, {}, "velocity_scaling", 1e-3, 1, fields, &scaling);
  fields->CheckKnown(run, {}, {"format", "version", "robot", "address", "camera", "device", "velocity_scaling", "seed",
                               "grey_noise", "blur_px", "supersampling", "faults", "camera_mode"});
}

}  // namespace

Result<SimCellOptions> SimCellOptionsFor(const std::string& run_json_text, const std::string& name) {
  JsonFields fields(run_json_text, name);
  const std::optional<json> parsed = fields.ParseObject();
  if (!parsed) return fields.ToStatus();
  const json& run = *parsed;
  RunBackends backends;
  ReadRunHeader(run, &fields, &backends);
  SimCellOptions o;
  uint64_t seed = 0;
  GetSeed(run, &fields, &seed);
  GetDoubleIn(run, {}, "grey_noise", 0, 50, &fields, &o.camera.render.noise_std_grey);
  GetDoubleIn(run, {}, "blur_px", 0, 10, &fields, &o.camera.render.blur_sigma_px);
  int& supersampling = o.camera.render.supersampling;
  if (fields.GetInt(run, {}, "supersampling", &supersampling) && (supersampling < 1 || supersampling > 8)) {
    AddOutOfRange(JsonPath{}.Member("supersampling"), "1", "8", supersampling, &fields);
  }
  ParseFaults(run, &fields, &o.faults);
  if (!fields.ok()) return fields.ToStatus();
  o.world.world_seed = seed;
  o.world.noise_seed = seed;
  o.world.pixel_noise_px = 0.02;  // the centroid noise the solvers are told (measured 0.01 px at grey noise 2)
  return o;
}

Result<RunBackends> ReadRunBackends(const std::string& run_json_text, const std::string& name) {
  JsonFields fields(run_json_text, name);
  const std::optional<json> parsed = fields.ParseObject();
  if (!parsed) return fields.ToStatus();
  RunBackends backends;
  ReadRunHeader(*parsed, &fields, &backends);
  if (!fields.ok()) return fields.ToStatus();
  backends.robot_at = fields.At(JsonPath{}.Member("robot"));
  return backends;
}

}  // namespace selfcal::simulation
