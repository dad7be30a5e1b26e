#include "io/dh_config_file.h"

#include <sstream>

#include "io/atomic_file.h"
#include "io/transform_yaml.h"
#include "io/yaml_writer.h"

namespace selfcal::io {
namespace {

std::string Mm(double m) { return YamlNumber(m * 1000.0 + 0.0); }
std::string Deg(double rad) { return YamlNumber(RadToDeg(rad) + 0.0); }

const char* ConventionKey(const DhTable& table) {
  if (table.convention == DhConvention::kStandard) return "standard";
  return table.hayati ? "modified_hayati" : "modified";
}

const char* RowComment(const DhTable& table) {
  if (table.convention == DhConvention::kStandard) return "link i: Rz(q + theta_offset) Tz(d) Tx(a) Rx(alpha)";
  return table.hayati ? "link i: Rx(alpha) Tx(a) Ry(beta) Rz(q + theta_offset) Tz(d)"
                      : "link i: Rx(alpha) Tx(a) Rz(q + theta_offset) Tz(d)";
}

}  // namespace

std::string DhRobotConfigText(const DhTable& table, const std::string& name, const std::string& source) {
  std::ostringstream out;
  out << "# The calibrated robot as a " << ConventionKey(table)
      << " DH table, the convention of the robot config it was calibrated from\n"
      << "# (selfcal, docs/calibrated-model-format.md). Lengths in mm, angles in degrees.\n"
      << "name: " << YamlQuoted(name) << "\n";
  if (!source.empty()) out << "source: " << YamlQuoted(source) << "\n";
  out << "dh_convention: " << ConventionKey(table) << "\n"
      << "joints:  # " << RowComment(table) << "\n";
  for (size_t i = 0; i < table.rows.size(); ++i) {
    const DhRow& r = table.rows[i];
    out << "  - {a_mm: " << Mm(r.a) << ", alpha_deg: " << Deg(r.alpha);
    if (table.hayati) out << ", beta_deg: " << Deg(i < table.betas.size() ? table.betas[i] : 0.0);
    out << ", d_mm: " << Mm(r.d) << ", theta_offset_deg: " << Deg(r.theta) << ", min_deg: " << Deg(table.limits[i].min_rad)
        << ", max_deg: " << Deg(table.limits[i].max_rad) << "}\n";
  }
  out << "base_from_link0: " << TransformYaml(table.base_from_link0, TransformStyle::kMillimetreDegree) << "\n";
  if (table.convention != DhConvention::kStandard) {
    out << "link_n_from_flange: " << TransformYaml(table.link_n_from_flange, TransformStyle::kMillimetreDegree)
        << "\n";
  }
  out << "flange_from_cam: " << TransformYaml(table.flange_from_cam, TransformStyle::kMillimetreDegree) << "\n";
  return out.str();
}

Status SaveDhRobotConfig(const DhTable& table, const std::string& name, const std::string& source,
                         const std::string& path) {
  return WriteFileAtomically(path, DhRobotConfigText(table, name, source));
}

}  // namespace selfcal::io
