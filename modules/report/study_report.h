// JSON and text of the simulation study (Table 2, Fig. 6, the bundle adjustment against its bound) and
// of the two-view bound sweep. The study document keeps its own format ("selfcal-study", version 1).
#pragma once

#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "simulation/bound_sweep.h"
#include "simulation/study.h"

namespace selfcal::report {

nlohmann::json StudyJson(const simulation::StudyReport& study, const simulation::StudyOptions& options);
void PrintStudyTables(const simulation::StudyReport& study, std::ostream& out);

nlohmann::json BoundSweepJson(const std::vector<simulation::BoundPoint>& sweep);
void PrintBoundSweep(const std::vector<simulation::BoundPoint>& sweep, std::ostream& out);

namespace internal {
// Shared by the study's JSON and text: a Stat as {n, mean, sd, rms, p90, max}; a / b or NaN.
nlohmann::json StatJson(const simulation::Stat& s);
double Ratio(double a, double b);
}  // namespace internal

}  // namespace selfcal::report
