#include "report/study_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "report/literature.h"

namespace selfcal::report {

namespace {

using internal::Ratio;

// A failure message cut for a table line (the JSON keeps it whole).
std::string Shortened(const std::string& message) {
  return message.size() <= 160 ? message : message.substr(0, 157) + "...";
}

// min, mean and max of the per-parameter RMS error / RMS bound, with the extreme parameters' names.
struct RatioSummary {
  int n = 0;
  double min = NAN, mean = NAN, max = NAN;
  std::string min_name, max_name;
};
RatioSummary SummarizeParameterRatios(const simulation::StudyCell& c) {
  RatioSummary r;
  double sum = 0;
  for (const auto& [name, error] : c.bundle_parameter_error) {
    auto bound = c.bundle_parameter_bound.find(name);
    if (bound == c.bundle_parameter_bound.end()) continue;
    const double ratio = Ratio(error.Rms(), bound->second.Rms());
    if (!std::isfinite(ratio)) continue;
    if (r.n == 0 || ratio < r.min) r.min = ratio, r.min_name = name;
    if (r.n == 0 || ratio > r.max) r.max = ratio, r.max_name = name;
    sum += ratio;
    ++r.n;
  }
  if (r.n > 0) r.mean = sum / r.n;
  return r;
}

// The flat-sheet warning, the Table 2 heading and the centroid table of rendered cells.
void PrintHeaderAndCentroids(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  if (study.flat_sheet) {
    out << "FLAT DOT SHEET: every dot on one plane. The paper's factor method is degenerate there: the paper\n"
           "pipeline rows below count only the runs it completed ('runs' column; failures listed at the end),\n"
           "nan where it completed none. The kinematic bundle adjustment starts from the nominal model then.\n\n";
  }
  out << "Table 2 reproduction: pose measurement errors, mean / SD over pose pairs and runs\n";
  out << "(position with the eq. (21) scale and k_1 from the true first motion; bound rows are RMS)\n";
  bool any_rendered = false;
  for (const simulation::StudyCell& c : study.cells) any_rendered = any_rendered || c.rendered;
  if (any_rendered) {
    out << "Centroids on rendered images (detector vs truth, per coordinate, pooled over poses and runs; rows\n"
           "'<trajectory>/<level>' below use these pixels, their noise column is the noise the solvers are told)\n";
    std::snprintf(line, sizeof(line), "%-22s %9s %7s %8s %12s %12s %12s %12s\n", "trajectory/level", "dots", "missed",
                  "spurious", "RMS vs area", "RMS vs proj", "max vs proj", "ellipse bias");
    out << line;
    for (const simulation::StudyCell& c : study.cells) {
      if (!c.rendered) continue;
      double worst = 0;
      for (double e : c.centroids.vs_projected_px) worst = std::max(worst, std::abs(e));
      std::snprintf(line, sizeof(line), "%-22s %9d %7d %8d %9.4f px %9.4f px %9.4f px %9.4f px\n", c.trajectory.c_str(),
                    c.centroids.expected, c.centroids.missed, c.centroids.spurious,
                    simulation::CentroidErrors::Rms(c.centroids.vs_area_centroid_px),
                    simulation::CentroidErrors::Rms(c.centroids.vs_projected_px), worst,
                    simulation::CentroidErrors::Rms(c.centroids.ellipse_bias_px));
      out << line;
    }
    out << "\n";
  }
}

// Table 2 rows per cell: the paper pipeline, with the true scale, OpenCV, and the two-view bounds.
void PrintTable2Rows(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  std::snprintf(line, sizeof(line), "%-10s %-6s %-28s %9s %9s %10s %10s %8s %8s %6s\n", "trajectory", "noise",
                "method", "pos M mm", "pos SD", "ori M e-4", "ori SD", "fx M px", "fx SD", "runs");
  out << line;
  auto row = [&](const simulation::StudyCell& c, const char* method, const simulation::Stat& p, const simulation::Stat& o,
                 const simulation::Stat* f, bool rms) {
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9.4f %10.4f %10.4f %8.4f %8.4f %6d\n",
                  c.trajectory.c_str(), c.noise_px, method, rms ? p.Rms() : p.Mean(), rms ? NAN : p.Sd(),
                  rms ? o.Rms() : o.Mean(), rms ? NAN : o.Sd(), f ? (rms ? f->Rms() : f->Mean()) : NAN,
                  f && !rms ? f->Sd() : NAN, c.runs - c.runs_failed);
    out << line;
  };
  for (const simulation::StudyCell& c : study.cells) {
    row(c, "paper pipeline", c.position_mm, c.orientation_1e4rad, &c.fx_px, false);
    row(c, "paper pipeline, true scale", c.position_true_scale_mm, c.orientation_1e4rad, nullptr, false);
    if (c.opencv_position_mm.count() > 0) {
      row(c, "OpenCV E+recoverPose true fx", c.opencv_position_mm, c.opencv_orientation_1e4rad, nullptr, false);
    }
    if (c.bound_position_mm_fx_unknown.count() > 0) {
      row(c, "CRB fx unknown (RMS)", c.bound_position_mm_fx_unknown, c.bound_orientation_1e4rad_fx_unknown,
          &c.bound_fx_px, true);
      row(c, "CRB fx known (RMS)", c.bound_position_mm_fx_known, c.bound_orientation_1e4rad_fx_known, nullptr, true);
    }
  }
}

// Fig. 6: the verification poses with the nominal and the calibrated model.
void PrintFig6(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  out << "\nFig. 6 and 'does calibration help?': verification poses, nominal model vs calibrated\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %14s %14s %14s %14s %14s %14s\n", "trajectory", "noise",
                "3-D nom mm", "3-D cal mm", "3-D cal p90", "pose nom mm", "pose cal mm", "ori cal e-4");
  out << line;
  for (const simulation::StudyCell& c : study.cells) {
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f\n", c.trajectory.c_str(),
                  c.noise_px, c.error3d_nominal_mm.Mean(), c.error3d_calibrated_mm.Mean(),
                  c.error3d_calibrated_mm.Percentile(90), c.pose_position_nominal_mm.Mean(),
                  c.pose_position_calibrated_mm.Mean(), c.pose_orientation_calibrated_1e4rad.Mean());
    out << line;
  }
}

// The kinematic bundle adjustment rows beside Table 2, and its Cramer-Rao rows.
void PrintBundleRows(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  out << "\nBeyond the paper: kinematic bundle adjustment (BA), same runs. Relative poses reference -> identification\n"
         "pose i predicted by the BA model vs truth (the poses of the Table 2 rows), mean / SD; CRB rows: the BA's own\n"
         "Cramer-Rao bound at the truth, RMS; 'runs' = converged BA runs\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %-28s %9s %9s %10s %10s %8s %8s %6s\n", "trajectory", "noise",
                "method", "pos M mm", "pos SD", "ori M e-4", "ori SD", "fx M px", "fx SD", "runs");
  out << line;
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_runs == 0) continue;
    const int ok = c.bundle_runs - c.bundle_runs_failed;
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9.4f %10.4f %10.4f %8.4f %8.4f %6d\n",
                  c.trajectory.c_str(), c.noise_px, "kinematic BA", c.bundle_position_mm.Mean(),
                  c.bundle_position_mm.Sd(), c.bundle_orientation_1e4rad.Mean(), c.bundle_orientation_1e4rad.Sd(),
                  c.bundle_fx_px.Mean(), c.bundle_fx_px.Sd(), ok);
    out << line;
    if (c.bundle_bound_position_mm.count() > 0) {
      std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9s %10.4f %10s %8.4f %8s %6d\n",
                    c.trajectory.c_str(), c.noise_px, "BA CRB (RMS)", c.bundle_bound_position_mm.Rms(), "",
                    c.bundle_bound_orientation_1e4rad.Rms(), "", c.bundle_bound_fx_px.Rms(), "", ok);
      out << line;
    }
  }
}

// The bundle adjustment against its bound: RMS ratios, coverage, per-parameter ratios.
void PrintBundleAgainstBound(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  out << "\nBA against its bound: RMS error / RMS bound; coverage: free parameters and f_x whose truth lies within\n"
         "+-2 reported sigma (pooled over runs)\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %10s %10s %7s %10s %10s %7s %9s %9s %7s %9s %9s\n", "trajectory",
                "noise", "pos RMS mm", "CRB mm", "ratio", "ori RMS e-4", "CRB e-4", "ratio", "fx RMS px", "CRB px",
                "ratio", "cover 2s", "ms/solve");
  out << line;
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_runs == 0) continue;
    const double p = c.bundle_position_mm.Rms(), pb = c.bundle_bound_position_mm.Rms();
    const double o = c.bundle_orientation_1e4rad.Rms(), ob = c.bundle_bound_orientation_1e4rad.Rms();
    const double f = c.bundle_fx_px.Rms(), fb = c.bundle_bound_fx_px.Rms();
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %10.4f %10.4f %7.3f %10.4f %10.4f %7.3f %9.4f %9.4f %7.3f %8.1f%% %9.1f\n",
                  c.trajectory.c_str(), c.noise_px, p, pb, Ratio(p, pb), o, ob, Ratio(o, ob), f, fb, Ratio(f, fb),
                  100 * c.BundleCoverage(), 1e3 * c.bundle_seconds.Mean());
    out << line;
  }
  for (const simulation::StudyCell& c : study.cells) {
    if (c.noise_px != 0 || c.bundle_length_error_mm.count() + c.bundle_angle_error_deg.count() == 0) continue;
    std::snprintf(line, sizeof(line),
                  "%-10s %-6.2f no noise: largest |error| of the free parameters %.3g mm (lengths), %.3g deg "
                  "(angles), f_x %.3g px\n",
                  c.trajectory.c_str(), c.noise_px, c.bundle_length_error_mm.Max(), c.bundle_angle_error_deg.Max(),
                  c.bundle_fx_px.Max());
    out << line;
  }
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_weak_held.empty()) continue;
    std::string held;
    for (const auto& [name, runs] : c.bundle_weak_held) {
      held += (held.empty() ? "" : ", ") + name + " " + std::to_string(runs);
    }
    std::snprintf(line, sizeof(line),
                  "%-10s %-6.2f %d of %d runs held weak parameters at the description (%s): left out of the coverage "
                  "and the per-parameter ratios, %d runs scored\n",
                  c.trajectory.c_str(), c.noise_px, c.bundle_runs_weak_held, c.bundle_runs, held.c_str(),
                  c.bundle_runs_in_truths_gauge);
    out << line;
  }
  for (const simulation::StudyCell& c : study.cells) {
    const RatioSummary r = SummarizeParameterRatios(c);
    if (r.n == 0) continue;
    std::snprintf(line, sizeof(line),
                  "%-10s %-6.2f per-parameter RMS error / Cramer-Rao std, %d free parameters: mean %.3f, min %.3f "
                  "(%s), max %.3f (%s)\n",
                  c.trajectory.c_str(), c.noise_px, r.n, r.mean, r.min, r.min_name.c_str(), r.max, r.max_name.c_str());
    out << line;
  }
}

// Fig. 6 with the bundle adjustment model.
void PrintBundleFig6(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  out << "\nFig. 6 with the BA model: verification poses (paper pipeline's calibrated model beside it)\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %14s %14s %14s %14s %14s %14s %14s\n", "trajectory", "noise",
                "3-D paper mm", "3-D BA mm", "3-D BA p90", "pose paper mm", "pose BA mm", "pose CRB mm", "ori BA e-4");
  out << line;
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_runs == 0) continue;
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f\n",
                  c.trajectory.c_str(), c.noise_px, c.error3d_calibrated_mm.Mean(), c.bundle_error3d_mm.Mean(),
                  c.bundle_error3d_mm.Percentile(90), c.pose_position_calibrated_mm.Mean(),
                  c.bundle_pose_position_mm.Mean(), c.bundle_bound_pose_position_mm.Rms(),
                  c.bundle_pose_orientation_1e4rad.Mean());
    out << line;
  }
}

// The bundle adjustment 3-D error of the check distances: actual, predicted and bound.
void PrintBundlePredicted(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  out << "\nBA 3-D error of the check distances: actual RMS / predicted (each run's own covariance and pixel noise,\n"
         "quadratic mean of the per-distance std; parts: parameters, verification pixels) / bound (Cramer-Rao\n"
         "covariance at the truth, same propagation)\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %12s %12s %12s %12s %12s %9s %9s\n", "trajectory", "noise",
                "3-D RMS mm", "predicted", "pred param", "pred pixel", "bound", "act/pred", "act/bound");
  out << line;
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_runs == 0 || c.bundle_predicted3d_mm.count() == 0) continue;
    const double a = c.bundle_error3d_mm.Rms(), p = c.bundle_predicted3d_mm.Rms(), b = c.bundle_bound3d_mm.Rms();
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %12.4f %12.4f %12.4f %12.4f %12.4f %9.3f %9.3f\n",
                  c.trajectory.c_str(), c.noise_px, a, p, c.bundle_predicted3d_parameters_mm.Rms(),
                  c.bundle_predicted3d_pixels_mm.Rms(), b, Ratio(a, p), Ratio(a, b));
    out << line;
  }
}

// The eq. (21) bias at noise 0, failed runs, and the totals.
void PrintBiasFailuresAndTotals(const simulation::StudyReport& study, std::ostream& out) {
  char line[512];
  if (study.paper_pipeline_note.empty()) out << "\neq. (21) bias: |nominal ratio / true ratio - 1| per pose, mean (max)\n";
  for (const simulation::StudyCell& c : study.cells) {
    if (c.noise_px != 0 || !study.paper_pipeline_note.empty()) continue;
    std::snprintf(line, sizeof(line), "%-10s %.3e (%.3e); position error at noise 0: %.4f mm mean, %.4f mm max\n",
                  c.trajectory.c_str(), c.scale_ratio_error.Mean(), c.scale_ratio_error.Max(), c.position_mm.Mean(),
                  c.position_mm.Max());
    out << line;
  }
  for (const simulation::StudyCell& c : study.cells) {
    if (c.runs_failed > 0) {
      out << c.trajectory << " noise " << c.noise_px << ": " << c.runs_failed << " of " << c.runs << " runs failed";
      if (!c.failures.empty()) out << " (first: " << Shortened(c.failures.front()) << ")";
      out << "\n";
    }
  }
  for (const simulation::StudyCell& c : study.cells) {
    if (c.bundle_runs_failed > 0) {
      out << c.trajectory << " noise " << c.noise_px << ": bundle adjustment did not converge in " << c.bundle_runs_failed
          << " of " << c.bundle_runs << " runs";
      if (!c.bundle_failures.empty()) out << " (first: " << Shortened(c.bundle_failures.front()) << ")";
      out << "\n";
    }
  }
  if (study.paper_pipeline_note.empty()) {
    std::snprintf(line, sizeof(line), "identifiable parameters: paper pipeline %d, bundle adjustment %d (+ f_x); total time %.1f s\n",
                  study.identifiable_parameters, study.bundle_free_parameters, study.seconds_total);
  } else {
    std::snprintf(line, sizeof(line), "identifiable parameters: bundle adjustment %d (+ f_x); total time %.1f s\n",
                  study.bundle_free_parameters, study.seconds_total);
  }
  out << line;
}

}  // namespace

void PrintStudyTables(const simulation::StudyReport& study, std::ostream& out) {
  if (study.paper_pipeline_note.empty()) {
    PrintHeaderAndCentroids(study, out);
    PrintTable2Rows(study, out);
    PrintFig6(study, out);
  } else {
    out << "configuration " << CameraMountName(study.configuration)
        << ": the paper pipeline's rows (Table 2, Fig. 6, the eq. (21) bias) are left out; the paper pipeline is "
        << study.paper_pipeline_note << "\n";
  }
  const bool any_bundle = std::any_of(study.cells.begin(), study.cells.end(),
                                      [](const simulation::StudyCell& c) { return c.bundle_runs > 0; });
  if (any_bundle) {
    PrintBundleRows(study, out);
    PrintBundleAgainstBound(study, out);
    PrintBundleFig6(study, out);
    PrintBundlePredicted(study, out);
  }
  PrintBiasFailuresAndTotals(study, out);
}

void PrintBoundSweep(const std::vector<simulation::BoundPoint>& sweep, std::ostream& out) {
  if (sweep.empty()) return;
  char line[256];
  // The paper's Table 2, optimal trajectory, at its nearest noise level (I = 0.2 px, II = 0.5 px).
  const double sigma = sweep.front().setup.sigma_px;
  const PaperTable2Row& paper = *NearestTable2Row("optimal", sigma);
  std::snprintf(line, sizeof(line),
                "\nTwo-view Cramer-Rao bound (RMS), %d points, sigma %.2f px, depth %.0f mm; paper's Table 2 "
                "optimal at noise %s: %.2fe-4 rad, %.2f mm, %.2f px\n",
                sweep.front().setup.num_points, sigma, sweep.front().setup.depth_m * kMmPerM,
                paper.noise_px > 0.35 ? "II" : "I", paper.orientation_1e4rad.mean, paper.position_mm.mean,
                paper.fx_px.mean);
  out << line;
  std::snprintf(line, sizeof(line), "%7s %7s %7s %9s %6s | %12s %10s %8s | %12s %10s\n", "fx px", "FOV deg", "spread",
                "base mm", "dots", "ori e-4 (f?)", "pos mm", "fx px", "ori e-4 (f)", "pos mm");
  out << line;
  for (const simulation::BoundPoint& p : sweep) {
    std::snprintf(line, sizeof(line), "%7.0f %7.1f %7.2f %9.0f %6d | %12.3f %10.4f %8.3f | %12.3f %10.4f%s\n",
                  p.setup.fx_px, p.horizontal_fov_deg, p.setup.depth_spread_ratio, p.baseline_m * kMmPerM, p.setup.num_points,
                  p.orientation_rad_fx_unknown * 1e4, p.position_m_fx_unknown * kMmPerM, p.fx_px,
                  p.orientation_rad_fx_known * 1e4, p.position_m_fx_known * kMmPerM,
                  p.ok_fx_unknown ? "" : "  (f_x unobservable)");
    out << line;
  }
}

}  // namespace selfcal::report
