// report.json's `methods.bundle.plot_data`: what report.html draws and the figures do not hold (the
// camera poses, the bundle's dots, every residual with its pixel, the correlations of the free
// parameters). Internal to the report module; docs/report-format.md describes it.
#pragma once

#include <nlohmann/json.hpp>

#include "calibration/bundle_stage.h"
#include "calibration/calibrate.h"
#include "observations/observation_set.h"

namespace selfcal::report {

// null when the bundle gave no model (its fit geometry is empty).
// Residual rows {pose, dot, pixel_px, residual_px}.
nlohmann::json ResidualsJson(const std::vector<calibration::ObservedResidual>& residuals);

nlohmann::json BundlePlotDataJson(const ObservationSet& observations, const calibration::BundleStageReport& stage);

// The same keys from a flange-pose set's pose-noise solve when it is the result (CalibrationReport::
// PoseNoiseIsTheResult): its camera poses, dots, residuals and the correlations of its hand-eye correction and
// estimated intrinsics.
nlohmann::json PoseNoisePlotDataJson(const ObservationSet& observations, const calibration::CalibrationReport& report);

}  // namespace selfcal::report
