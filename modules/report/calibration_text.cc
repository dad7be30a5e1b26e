#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>

#include "kinematics/joint_motion.h"
#include "report/calibration_report.h"

namespace selfcal::report {

namespace {

// The paper pipeline's outcome, one line: a long message (one clause per pose pair) cut to its first
// clause and the unused pairs counted by outcome (report.json lists them pair by pair). `bundle_follows`:
// the bundle ran after it and starts from the nominal model when the paper pipeline did not succeed.
void PrintPaperOutcome(const calibration::PaperPipelineReport& r, bool bundle_follows, std::ostream& out) {
  out << "outcome: " << calibration::OutcomeName(r.outcome);
  const bool success = r.outcome == calibration::Outcome::kSuccess;
  if (!success && bundle_follows) out << ", so the bundle starts from the nominal model";
  std::string message = r.message;
  constexpr size_t kShortMessage = 100;
  if (message.size() > kShortMessage && message.find("; ") != std::string::npos) {
    message = message.substr(0, message.find("; "));
    std::map<std::string, int> unused;
    for (const auto& m : r.measurements) {
      if (!m.used) ++unused[twoview::OutcomeName(m.two_view.outcome)];
    }
    for (const auto& [name, n] : unused) message += "; " + std::to_string(n) + " pairs " + name;
    message += "; each pair in report.json";
  }
  if (!message.empty()) out << " (" << message << ")";
  out << "\n";
}

void PrintPaperSummary(const calibration::PaperPipelineReport& r, bool bundle_follows, std::ostream& out) {
  PrintPaperOutcome(r, bundle_follows, out);
  int used = 0;
  for (const auto& m : r.measurements) used += m.used ? 1 : 0;
  out << "pose measurements: " << used << " of " << r.measurements.size() << " pairs used; f_x = " << std::fixed
      << std::setprecision(3) << r.fx_px << " px from " << r.fx_pairs << " pairs\n";
  out << "identifiable parameters: " << r.identifiability.rank << " of " << r.identifiability.num_parameters
      << " (condition number " << std::setprecision(1) << r.identifiability.condition_number << ")\n";
  if (r.identification.outcome != identification::Outcome::kNotRun) {
    out << "identification: " << identification::OutcomeName(r.identification.outcome) << ", "
        << r.identification.iterations << " iterations, residual RMS " << std::setprecision(3)
        << r.identification.rms_position_m * kMmPerM << " mm / " << RadToDeg(r.identification.rms_rotation_rad)
        << " deg\n";
  }
  if (r.yardstick.ok) {
    out << "yardstick scale: " << std::setprecision(6) << r.yardstick.scale << " +- " << r.yardstick.scale_sigma << "\n";
  } else if (!r.yardstick.message.empty()) {
    out << "yardstick: " << r.yardstick.message << "\n";
  }
  if (r.verification_calibrated.num_ok > 0) {
    out << "3-D error on " << r.verification_calibrated.num_ok << " held-out distances: nominal model "
        << std::setprecision(3) << r.verification_nominal.rms_error_m * kMmPerM << " mm RMS, calibrated "
        << r.verification_calibrated.rms_error_m * kMmPerM << " mm RMS (max " << r.verification_calibrated.max_error_m * kMmPerM
        << " mm)\n";
  }
  out << "time: " << std::setprecision(1) << r.seconds_total * 1e3 << " ms\n";
  out.unsetf(std::ios::floatfield);
}

// The held-out reprojection: overall for both models, and the verification poses above their own 95 %
// limit at the bundle's noise estimate, as figures: the verdict's test is the acceptance's, at the stated
// noise (acceptance.h), and at 95 % one pose in twenty of a correct model lies above its limit.
void PrintHeldOut(const calibration::HeldOutReprojection& c, const calibration::HeldOutReprojection& n,
                  const char* noise_label, std::ostream& out) {
  if (!c.ok) {
    if (!c.message.empty()) out << "  held-out reprojection: not computed (" << c.message << ")\n";
    return;
  }
  const calibration::HeldOutFigure& f = c.overall;
  out << std::fixed << std::setprecision(3) << "  held-out reprojection on " << c.poses.size() << " verification poses, "
      << f.num_residuals << " dots: RMS " << f.rms_px << " px per coordinate";
  if (std::isfinite(c.rms_mm)) out << " (" << c.rms_mm << " mm at the scene)";
  out << "\n    at " << noise_label << " " << c.noise_px << " px: chi-square " << std::setprecision(1)
      << f.chi_square << " for " << f.dof << " dof, 95 % limit " << f.chi_square_limit
      << (f.noise_dof > 0 ? " (F test)" : "");
  if (f.pose_noise_dof > 0) {
    out << " (pose errors " << f.pose_share << " of the dof, their size estimated from " << f.pose_noise_dof << " dof)";
  }
  out << (f.test_passed ? ": within" : ": above") << "\n";
  if (!c.prediction_uncertainty) out << "    (the parameters' uncertainty is not in the test: " << c.message << ")\n";
  if (n.ok) {
    out << std::setprecision(3) << "    nominal model on the same images: RMS " << n.overall.rms_px << " px ("
        << n.overall.num_residuals << " dots); the calibrated model " << (f.rms_px < n.overall.rms_px ? "beats" : "does not beat")
        << " it\n";
  }
  std::ostringstream above;
  int num_above = 0;
  for (const calibration::HeldOutFigure& p : c.poses) {
    if (p.test_passed) continue;
    ++num_above;
    above << std::fixed << std::setprecision(3) << "      " << p.pose_id << ": RMS " << p.rms_px << " px over "
          << p.num_residuals << " dots, chi-square " << std::setprecision(1) << p.chi_square << " (limit "
          << p.chi_square_limit << ")\n";
  }
  if (num_above > 0) {
    out << std::setprecision(1) << "    poses above their own 95 % limit at that noise: " << num_above << " of "
        << c.poses.size() << " (" << 0.05 * static_cast<double>(c.poses.size()) << " expected by chance)\n"
        << above.str();
  }
  out.unsetf(std::ios::floatfield);
}

// " + f_x + k1 + ...": the estimated intrinsics after the free kinematic count.
std::string EstimatedIntrinsicsText(const IntrinsicsMask& estimated) {
  std::string out;
  for (int k : EstimatedIntrinsics(estimated)) out += std::string(" + ") + (k == kFx ? "f_x" : IntrinsicName(k));
  return out;
}

// The estimated intrinsics other than f_x with their standard deviations, one line; nothing when none.
void PrintLensSummary(const bundle::BundleReport& b, std::ostream& out) {
  std::string line;
  for (int k : EstimatedIntrinsics(b.intrinsics_estimated)) {
    if (k == kFx) continue;
    const bool px = k == kCx || k == kCy;
    std::ostringstream term;
    term << std::setprecision(px ? 5 : 4) << IntrinsicName(k) << " = " << b.intrinsics[k] << " +- "
         << std::setprecision(2) << b.intrinsics_stddev[k] << (px ? " px" : "");
    line += (line.empty() ? "" : ", ") + term.str();
  }
  if (!line.empty()) out << "  intrinsics: " << line << "\n";
}

// The joints that barely move and the parameters held because the data determine them too poorly.
void PrintWeakDirections(const bundle::BundleReport& b, std::ostream& out) {
  for (const BarelyMovingJoint& j : b.barely_moving) {
    out << "  " << BarelyMovesSentence(j, "the identification poses") << "\n";
  }
  for (const bundle::WeakParameter& w : b.weak) {
    const double scale = w.length ? kMmPerM : RadToDeg(1.0);
    const char* unit = w.length ? " mm" : " deg";
    out << "  held (weak): " << w.name << " at the robot description's value: these poses determine it only to +- "
        << std::setprecision(3) << w.conditional_std * scale << unit
        << (w.under_error_model ? " under the estimated pose error (tolerance " : " given the others (tolerance ")
        << w.tolerance * scale << unit << (w.under_error_model ? "; " : "; the direction ") << w.combination << ")\n";
  }
}

// `heldout`: the held-out reprojection to print (the stage's, or the pose-noise solve's when that is the result:
// printed after it, then).
void PrintBundleSummary(const calibration::BundleStageReport& stage, bool flange_poses,
                        const calibration::HeldOutReprojection* heldout, std::ostream& out) {
  const bundle::BundleReport& b = stage.bundle;
  out << (flange_poses ? "hand-eye bundle adjustment (recorded flange poses): " : "kinematic bundle adjustment: ")
      << bundle::OutcomeName(b.outcome);
  // A converged solve's message repeats the figures of the lines below.
  if (!b.message.empty() && b.outcome != bundle::Outcome::kConverged) out << " (" << b.message << ")";
  out << "\n  start: " << stage.start_note << "\n";
  if (b.rho.size() == 0) return;
  out << "  " << b.free_names.size() << (flange_poses ? " free hand-eye parameters" : " free kinematic parameters")
      << EstimatedIntrinsicsText(b.intrinsics_estimated) << ", " << b.fixed_names.size() << " fixed";
  if (!b.held_names.empty()) out << " (" << b.held_names.size() << " held by request)";
  out << "; " << b.num_observations << " observations, " << b.removed.size() << " removed by the screen, "
      << b.dropped_dots.size() << " dots dropped\n";
  PrintWeakDirections(b, out);
  // Ceres's termination text up to its first sentence ("CONVERGENCE: Function tolerance reached"); report.json
  // keeps it whole.
  out << "  " << b.iterations << " iterations (" << b.termination.substr(0, b.termination.find('.'))
      << "), reprojection RMS " << std::setprecision(4)
      << b.rms_reprojection_px << " px; f_x = " << std::fixed << std::setprecision(3) << b.fx_px;
  // A held f_x has no std: it is the stated camera's value.
  if (b.intrinsics_estimated[kFx]) {
    out << " +- " << b.fx_stddev << " px\n";
  } else {
    out << " px (held)\n";
  }
  out.unsetf(std::ios::floatfield);
  if (b.error_model.estimated) {
    out << "  error model from the residuals (the sigmas' model): pixel noise " << std::setprecision(3)
        << b.error_model.pixel_px << " px, camera pose per image " << b.error_model.pose_translation_m * kMmPerM << " mm / "
        << RadToDeg(b.error_model.pose_rotation_rad) << " deg per axis";
    if (b.error_model.joint_rad >= 0) out << ", joint readings " << RadToDeg(b.error_model.joint_rad) << " deg";
    out << "\n";
  }
  PrintLensSummary(b, out);
  if (stage.verification.num_ok > 0) {
    out << "  3-D error on " << stage.verification.num_ok << " held-out distances: nominal model " << std::fixed
        << std::setprecision(3) << stage.verification_nominal.rms_error_m * kMmPerM << " mm RMS, bundle "
        << stage.verification.rms_error_m * kMmPerM << " mm RMS (max " << stage.verification.max_error_m * kMmPerM << " mm)\n";
  }
  if (stage.predicted_error.ok) {
    out << "  predicted 3-D error (first order): " << std::fixed << std::setprecision(3) << stage.predicted_error.rms_std_m * kMmPerM
        << " mm RMS (calibrated parameters " << stage.predicted_error.rms_parameters_std_m * kMmPerM
        << " mm, verification pixels " << stage.predicted_error.rms_pixels_std_m * kMmPerM << " mm)\n";
    out.unsetf(std::ios::floatfield);
  }
  if (heldout != nullptr) PrintHeldOut(*heldout, stage.heldout_nominal, "the bundle's noise estimate", out);
  out << "  time: " << std::fixed << std::setprecision(1) << b.seconds * 1e3 << " ms solve, "
      << stage.seconds_verification * 1e3 << " ms distances, " << stage.seconds_heldout * 1e3 << " ms held-out, "
      << stage.seconds_fit_geometry * 1e3 << " ms fit geometry, " << stage.seconds_predicted_error * 1e3
      << " ms predicted error; stage " << stage.seconds_total * 1e3 << " ms\n";
  out.unsetf(std::ios::floatfield);
}

// The pose-noise solve of a flange-pose set when it is the result: the figures the model written carries.
void PrintPoseNoiseResult(const calibration::CalibrationReport& report, std::ostream& out) {
  const bundle::PoseNoiseReport& n = *report.pose_noise;
  out << "the model written is the pose-noise solve's (flange pose noise " << std::setprecision(3)
      << report.pose_noise_translation_m * kMmPerM << " mm / " << RadToDeg(report.pose_noise_rotation_rad)
      << " deg per axis): f_x = " << std::fixed << std::setprecision(3) << n.intrinsics[kFx];
  if (n.intrinsics_estimated[kFx]) {
    out << " +- " << n.intrinsics_stddev[kFx] << " px";
  } else {
    out << " px (held)";
  }
  out << ", reprojection RMS " << std::setprecision(4) << n.rms_reprojection_px << " px at the corrected flange poses\n";
  out.unsetf(std::ios::floatfield);
  if (report.pose_noise_heldout && report.bundle) {
    PrintHeldOut(*report.pose_noise_heldout, report.bundle->heldout_nominal,
                 "the stated pixel noise (with the flange pose noise)", out);
  }
}

}  // namespace

// The hand-eye start of a flange-pose set and, when accepted, the calibrated transform with its sigmas.
void PrintHandEye(const calibration::CalibrationReport& report, std::ostream& out) {
  const calibration::HandEyeStartReport& start = *report.hand_eye_start;
  out << "hand-eye start from the images and the flange motions: " << (start.ok ? "" : "failed: ") << start.message
      << "\n";
  out << "metric scale: the flange translations"
      << (report.flange_scale_yardsticks > 0
              ? " and " + std::to_string(report.flange_scale_yardsticks) + " yardstick length constraint(s)"
              : "")
      << "\n";
  if (!report.model || !report.bundle) return;
  const bool eye_to_hand = report.model->robot.mount == CameraMount::kEyeToHand;
  const Rigid3& x = eye_to_hand ? report.model->robot.base_from_cam : report.model->robot.flange_from_cam;
  const Eigen::Vector3d rotvec = LogSO3(x.rotation);
  const Eigen::Matrix<double, 6, 1>& sd = eye_to_hand ? report.model->base_from_cam_stddev : report.model->flange_from_cam_stddev;
  out << std::fixed << std::setprecision(3) << (eye_to_hand ? "base_from_cam" : "flange_from_cam") << ": translation [" << x.translation.x() * kMmPerM << ", "
      << x.translation.y() * kMmPerM << ", " << x.translation.z() * kMmPerM << "] mm, rotation vector ["
      << RadToDeg(rotvec.x()) << ", " << RadToDeg(rotvec.y()) << ", " << RadToDeg(rotvec.z()) << "] deg";
  if (sd.allFinite()) {
    out << "; std " << sd[0] * kMmPerM << ", " << sd[1] * kMmPerM << ", " << sd[2] * kMmPerM << " mm, " << RadToDeg(sd[3]) << ", "
        << RadToDeg(sd[4]) << ", " << RadToDeg(sd[5]) << " deg (camera frame)";
  }
  out << "\n";
  out.unsetf(std::ios::floatfield);
  if (report.pose_noise) {
    out << "with the flange pose noise " << (report.pose_noise_estimated ? "estimated from the residuals" : "stated")
        << " (" << report.pose_noise_translation_m * kMmPerM << " mm / " << RadToDeg(report.pose_noise_rotation_rad)
        << " deg per axis): " << (report.pose_noise->ok ? "" : "not solved: ")
        << report.pose_noise->message << "\n";
  }
  if (report.motion_check) {
    out << "camera motions from the images alone against the flange motions: "
        << (report.motion_check->ok ? "" : "not available: ") << report.motion_check->message << "\n";
  }
}

// The k-fold held-out figure of a set without verification poses.
void PrintCrossValidation(const calibration::CrossValidationReport& cv, std::ostream& out) {
  out << "  cross-validation (" << cv.folds << " folds over the identification poses, seed " << cv.seed << "): ";
  if (!cv.ran || cv.pooled.num_residuals == 0) {
    out << cv.message << "\n";
    return;
  }
  out << "held-out RMS " << std::fixed << std::setprecision(3) << cv.pooled.rms_px << " px per coordinate";
  if (std::isfinite(cv.rms_mm)) out << " (" << cv.rms_mm << " mm at the scene)";
  out << "; folds";
  for (const calibration::CrossValidationFold& f : cv.per_fold) {
    if (f.figure.num_residuals > 0) {
      out << " " << f.figure.rms_px;  // fixed, 3 decimals as above
    } else {
      out << " -";
    }
  }
  out << " px; " << cv.folds_passed << " of " << cv.folds << " pass the held-out test at the stated noise";
  if (cv.pooled.dof > 0) {
    out << "; pooled chi-square " << std::setprecision(1) << cv.pooled.chi_square << " over " << cv.pooled.dof
        << " (95 % limit " << cv.pooled.chi_square_limit << ")";
  }
  out << "\n";
  out.unsetf(std::ios::floatfield);
}

namespace {

// Which flange-pose solve is the result, and the held-out figures that chose it.
void PrintModelChoice(const calibration::ModelChoice& c, std::ostream& out) {
  out << "  the result: ";
  if (!c.made) {
    out << "the pose-noise solve (not chosen by cross-validation: " << c.message << ")\n";
    return;
  }
  out << std::fixed << std::setprecision(3)
      << (c.pose_noise_chosen ? "the pose-noise solve" : "the exact-pose solve (flange poses as recorded)")
      << ": cross-validated on the identification poses (" << c.folds << " folds, seed " << c.seed
      << "), the exact-pose solve predicts them at " << c.exact_pose_rms_px << " px, the pose-noise solve at "
      << c.pose_noise_rms_px << " px\n";
  out.unsetf(std::ios::floatfield);
}

// Pose ids, at most `max` of them, then how many more.
std::string PoseList(const std::vector<std::string>& ids, std::size_t max = 6) {
  std::string s;
  for (std::size_t i = 0; i < ids.size() && i < max; ++i) s += (i ? ", " : "") + ids[i];
  if (ids.size() > max) s += ", ... (" + std::to_string(ids.size()) + " in all)";
  return s;
}

// Whether the images see the scene in one place, and what the calibration did when they do not.
void PrintSceneSplit(const calibration::SceneSplit& split, std::ostream& out) {
  out << std::fixed << std::setprecision(2);
  if (!split.found) {
    out << "  one scene: the " << split.images << " images see its points in one place (one move of them per best "
        << "split of the images in two would leave " << split.rms_two_places_px << " px RMS of "
        << split.rms_one_place_px << ")\n";
  } else {
    out << "  the scene moved between poses: " << split.second_poses.size() << " poses (" << PoseList(split.second_poses)
        << ") see its points " << split.translation_m * 1e3 << " mm and " << RadToDeg(split.rotation_rad)
        << " deg from where " << split.first_poses.size() << " poses (" << PoseList(split.first_poses)
        << ") see them (a move per group leaves " << split.rms_two_places_px << " px RMS of "
        << split.rms_one_place_px << "); " << split.decision;
    if (split.one_scene_heldout_px > 0 && split.split_heldout_px > 0) {
      out << std::setprecision(3) << " (held-out " << split.one_scene_heldout_px << " px with one scene, "
          << split.split_heldout_px << " px with a scene each)";
    }
    out << "\n";
  }
  out.unsetf(std::ios::floatfield);
}

void PrintSummaryLines(const calibration::CalibrationReport& report, std::ostream& out) {
  if (report.hand_eye_start) {
    PrintHandEye(report, out);
  } else {
    out << "paper pipeline (Meng & Zhuang):\n";
    PrintPaperSummary(report.paper, report.bundle.has_value(), out);
  }
  if (report.bundle) {
    out << "\n";
    const bool pose_noise = report.PoseNoiseIsTheResult();
    PrintBundleSummary(*report.bundle, report.hand_eye_start.has_value(), pose_noise ? nullptr : &report.bundle->heldout,
                       out);
    if (pose_noise) PrintPoseNoiseResult(report, out);
    if (report.cross_validation) PrintCrossValidation(*report.cross_validation, out);
    if (report.model_choice) PrintModelChoice(*report.model_choice, out);
    if (report.scene_split) PrintSceneSplit(*report.scene_split, out);
    for (const calibration::SceneMove& m : report.scene_moves) {
      out << "  scene `" << m.scene << "` against `" << m.relative_to << "`: its " << m.shared_points
          << " points lie " << std::fixed << std::setprecision(2) << m.displacement_rms_m * 1e3 << " mm RMS from the first's (largest "
          << m.displacement_max_m * 1e3 << " mm), a rigid move of " << RadToDeg(m.rotation_rad) << " deg (fit RMS "
          << m.rigid_fit_rms_m * 1e3 << " mm): " << (m.moved ? "the scene moved" : "no move beyond the points' scatter")
          << "\n";
      out.unsetf(std::ios::floatfield);
    }
  }
  if (!report.acceptance.checks.empty()) {
    out << "\nacceptance of the " << calibration::MethodName(report.method) << " model:\n";
    for (const calibration::AcceptanceCheck& c : report.acceptance.checks) {
      out << "  " << calibration::CheckStatusName(c.status) << (c.decisive ? "" : " (figure only)") << ": " << c.sentence
          << "\n";
    }
    if (!report.acceptance.Verified()) out << "  (not verified: nothing held out could test it)\n";
    out << "  time: " << std::fixed << std::setprecision(1) << report.seconds_acceptance * 1e3 << " ms\n";
    out.unsetf(std::ios::floatfield);
  }
  out << "\ncalibration time (every stage): " << std::fixed << std::setprecision(1) << report.seconds_total * 1e3
      << " ms\n";
  out.unsetf(std::ios::floatfield);
}

// "0.053 px (0.031 mm at the scene)": mm only when known.
std::string PxAndMm(double px, double mm) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3) << px << " px";
  if (std::isfinite(mm)) text << " (" << mm << " mm at the scene)";
  return text.str();
}

}  // namespace

void PrintCalibrationSummary(const ObservationSet& observations, const calibration::CalibrationReport& report,
                             std::ostream& out) {
  std::ostringstream text;
  text << "configuration: " << CameraMountName(observations.robot.mount)
       << (observations.robot.mount == CameraMount::kEyeToHand
               ? " (the camera fixed in the robot base frame, the points carried by the flange)\n"
               : " (the camera on the flange, the points fixed in the robot base frame)\n");
  PrintSummaryLines(report, text);
  out << WrapLines(text.str(), kSummaryLineWidth);
}

std::string VerdictHeadline(const calibration::CalibrationReport& report) {
  std::string line = calibration::VerdictName(report.verdict);
  const calibration::HeldOutReprojection* heldout = nullptr;
  if (report.bundle && report.bundle->heldout.ok) heldout = &report.bundle->heldout;
  if (report.PoseNoiseIsTheResult()) {
    heldout = report.pose_noise_heldout && report.pose_noise_heldout->ok ? &*report.pose_noise_heldout : nullptr;
  }
  if (report.method == calibration::Method::kPaper && report.paper_heldout && report.paper_heldout->calibrated.ok) {
    heldout = &report.paper_heldout->calibrated;
  }
  const calibration::CrossValidationReport* cv =
      report.cross_validation && report.cross_validation->ran && report.cross_validation->pooled.num_residuals > 0
          ? &*report.cross_validation
          : nullptr;
  if (heldout != nullptr) {
    line += ": held-out " + PxAndMm(heldout->overall.rms_px, heldout->rms_mm) + " on " +
            std::to_string(heldout->poses.size()) + " verification poses";
  } else if (cv != nullptr) {
    line += ": cross-validated " + PxAndMm(cv->pooled.rms_px, cv->rms_mm) + ", " + std::to_string(cv->folds) + " folds";
  } else {
    line += ": no held-out figure";
  }
  return line;
}

std::string WrapLines(const std::string& text, int width) {
  std::istringstream in(text);
  std::string result, line;
  while (std::getline(in, line)) {
    const size_t indent = line.find_first_not_of(' ') == std::string::npos ? 0 : line.find_first_not_of(' ');
    const std::string continuation(indent + 2, ' ');
    size_t start = 0;  // the first character of the part not yet written
    std::string prefix;
    while (static_cast<int>(prefix.size() + line.size() - start) > width) {
      const size_t limit = start + width - prefix.size();
      size_t cut = line.rfind(' ', limit);
      if (cut == std::string::npos || cut <= start + indent) cut = line.find(' ', limit);
      if (cut == std::string::npos) break;
      result += prefix + line.substr(start, cut - start) + "\n";
      start = line.find_first_not_of(' ', cut);
      if (start == std::string::npos) break;
      prefix = continuation;
    }
    if (start != std::string::npos && start < line.size()) result += prefix + line.substr(start);
    result += "\n";
  }
  return result;
}

}  // namespace selfcal::report
