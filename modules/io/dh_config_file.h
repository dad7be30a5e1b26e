// The calibrated robot written back as a robot config in the DH convention the user entered
// (docs/calibrated-model-format.md, "The calibrated robot in your convention"): the keys of
// config/robots/*.yaml (mm and degrees, 17 significant digits where needed), read by LoadRobotModel and by
// anyone's DH tools. The table comes from kinematics/dh_table.h ExpressAsDh, which decides whether the
// model is expressible; this file only writes it.
#pragma once

#include <string>

#include "base/status.h"
#include "kinematics/dh_table.h"

namespace selfcal::io {

// The robot config text of `table` (no `format:` key: a plain robot config).
std::string DhRobotConfigText(const DhTable& table, const std::string& name, const std::string& source);

// DhRobotConfigText written atomically to `path`.
Status SaveDhRobotConfig(const DhTable& table, const std::string& name, const std::string& source,
                         const std::string& path);

}  // namespace selfcal::io
