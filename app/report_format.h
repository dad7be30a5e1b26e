// JSON and on-screen forms of the pipeline and study reports. mm and degrees only here, with the unit
// in every key; SI everywhere else.
#pragma once

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "observations/observation_set.h"
#include "pipeline/bound_sweep.h"
#include "pipeline/bundle_stage.h"
#include "pipeline/paper_pipeline.h"
#include "pipeline/study.h"

namespace selfcal::app {

nlohmann::json CalibrationReportJson(const ObservationSet& observations, const pipeline::PaperPipelineReport& report);
void PrintCalibrationSummary(const pipeline::PaperPipelineReport& report, std::ostream& out);

// The `bundle` section of report.json: outcome, start, solver figures, removed observations by pose and
// dot, free and fixed names, every parameter's value and stddev (mm or deg, unit in the key), f_x,
// held-out verification. No timing (that goes under timing_s, so that reports compare byte for byte).
nlohmann::json BundleReportJson(const ObservationSet& observations, const pipeline::BundleStageReport& report);
void PrintBundleSummary(const pipeline::BundleStageReport& report, std::ostream& out);

nlohmann::json StudyJson(const pipeline::StudyReport& study, const pipeline::StudyOptions& options);
void PrintStudyTables(const pipeline::StudyReport& study, std::ostream& out);

nlohmann::json BoundSweepJson(const std::vector<pipeline::BoundPoint>& sweep);
void PrintBoundSweep(const std::vector<pipeline::BoundPoint>& sweep, std::ostream& out);

}  // namespace selfcal::app
