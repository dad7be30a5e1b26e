// The figures of a calibration's report.html, each drawn from a report.json document (the whole document
// or one of its sections) with plotly.js. A figure whose data the document lacks is left out, and the
// function says so in a note on the page. Internal to the report module.
//
// Units on the page: mm and degrees (the document is SI); pixels as px.
#pragma once

#include <nlohmann/json.hpp>

#include "report/html_writer.h"

namespace selfcal::report::html {

// The camera at every pose (calibrated model), its optical axis, the bundle's dots, the check distances
// and the base frame, in 3-D. `plot_data`: methods.bundle.plot_data; `verification`: the top level's.
void SceneFigure(const nlohmann::json& plot_data, const nlohmann::json& verification, Page* page);

// The reprojection residuals (identification: the bundle's final fit; held-out: the verification
// images with the calibrated model): a histogram of |r| against the density of a correct model at
// `noise_px`, a box per pose, and the residual vectors over the image.
void ResidualFigures(const nlohmann::json& plot_data, double noise_px, Page* page);

// Corrections (value - nominal) of the free parameters with +-1 sigma: lengths in mm, angles in degrees.
// `parameters`: a method section's parameter rows.
void CorrectionFigure(const nlohmann::json& parameters, Page* page);

// The correlation matrix of the estimated entries (methods.bundle.plot_data.correlation).
void CorrelationFigure(const nlohmann::json& plot_data, Page* page);

// Held-out reprojection per verification pose: RMS of both models against the noise, and each pose's
// chi-square over its 95 % limit. `heldout`: the top level's heldout_reprojection.
void HeldOutFigure(const nlohmann::json& heldout, Page* page);

// The 3-D error of each check distance, both models, with the predicted std as the calibrated bar's
// error. `verification`, `predicted`: the top level's verification and predicted_3d_error.
void CheckDistanceFigure(const nlohmann::json& verification, const nlohmann::json& predicted, Page* page);

}  // namespace selfcal::report::html
