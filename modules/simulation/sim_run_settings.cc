#include "simulation/sim_run_settings.h"

#include <set>
#include <vector>

namespace selfcal::simulation {

namespace {

// The value of `key` in `object` as T; a message naming `name` and the key when missing or mistyped.
template <typename T>
bool Get(const nlohmann::json& object, const std::string& key, const std::string& name, T* value,
         std::string* problem) {
  const auto it = object.find(key);
  if (it == object.end()) {
    *problem = name + ": key \"" + key + "\" is missing";
    return false;
  }
  try {
    *value = it->get<T>();
  } catch (const nlohmann::json::exception&) {
    *problem = name + ": key \"" + key + "\" = " + it->dump() + " has the wrong type";
    return false;
  }
  return true;
}

}  // namespace

bool IsSimulatedRun(const nlohmann::json& run_json) {
  return run_json.is_object() && run_json.value("robot", "") == "sim" && run_json.value("camera", "") == "sim";
}

Result<SimCellOptions> SimCellOptionsFor(const nlohmann::json& run_json, const std::string& name) {
  if (!run_json.is_object()) return Status::Error(ErrorCode::kInvalidInput, name + ": not a JSON object");
  SimCellOptions o;
  std::string problem;
  uint64_t seed = 0;
  nlohmann::json faults;
  if (!Get(run_json, "seed", name, &seed, &problem) ||
      !Get(run_json, "grey_noise", name, &o.camera.render.noise_std_grey, &problem) ||
      !Get(run_json, "blur_px", name, &o.camera.render.blur_sigma_px, &problem) ||
      !Get(run_json, "supersampling", name, &o.camera.render.supersampling, &problem) ||
      !Get(run_json, "faults", name, &faults, &problem)) {
    return Status::Error(ErrorCode::kInvalidInput, problem);
  }
  o.world.world_seed = seed;
  o.world.noise_seed = seed;
  o.world.pixel_noise_px = 0.02;  // the centroid noise the solvers are told (measured 0.01 px at grey noise 2)
  const std::pair<const char*, std::set<int>*> lists[] = {
      {"reject_moves", &o.faults.reject_moves},       {"protective_stop_moves", &o.faults.protective_stop_moves},
      {"hang_moves", &o.faults.hang_moves},           {"disconnect_moves", &o.faults.disconnect_moves},
      {"jog_after_moves", &o.faults.jog_after_moves}, {"slow_settle_moves", &o.faults.slow_settle_moves},
      {"stale_reads", &o.faults.stale_reads},         {"nan_reads", &o.faults.nan_reads},
      {"short_reads", &o.faults.short_reads}};
  for (const auto& [key, set] : lists) {
    std::vector<int> v;
    if (!Get(faults, key, name + " faults", &v, &problem)) return Status::Error(ErrorCode::kInvalidInput, problem);
    set->insert(v.begin(), v.end());
  }
  return o;
}

}  // namespace selfcal::simulation
