#include "report/image_residuals.h"

#include <cmath>
#include <cstdio>
#include <map>

namespace selfcal::report {

namespace {

struct ImageFigures {
  int used = 0, screened_out = 0;
  double sum2_px2 = 0, max_px = -1;
  int max_dot = -1;
  void Add(double r_px, int dot, bool used_in_fit) {
    used += used_in_fit ? 1 : 0;
    screened_out += used_in_fit ? 0 : 1;
    if (used_in_fit) sum2_px2 += r_px * r_px;
    if (r_px > max_px) {
      max_px = r_px;
      max_dot = dot;
    }
  }
};

std::string Number(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", value);
  return text;
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// Per pose id: the bundle's final fit and screen for identification images, the held-out prediction and its
// gross errors for verification images.
std::map<std::string, ImageFigures> FiguresByPose(const calibration::BundleStageReport& stage) {
  std::map<std::string, ImageFigures> figures;
  for (const calibration::ObservedResidual& r : stage.fit_geometry.identification_residuals) {
    figures[r.pose_id].Add(r.residual_px.norm(), r.dot_id, true);
  }
  if (!stage.fit_geometry.identification_residuals.empty()) {
    for (const bundle::RemovedObservation& r : stage.bundle.removed) figures[r.pose_id].Add(r.residual_px, r.dot_id, false);
  }
  for (const calibration::ObservedResidual& r : stage.heldout.residuals) {
    figures[r.pose_id].Add(r.residual_px.norm(), r.dot_id, true);
  }
  for (const calibration::ObservedResidual& r : stage.heldout.gross_errors) {
    figures[r.pose_id].Add(r.residual_px.norm(), r.dot_id, false);
  }
  return figures;
}

}  // namespace

std::string ImageResidualsCsv(const ObservationSet& observations, const calibration::CalibrationReport& report) {
  const bool fitted = report.bundle && !report.bundle->fit_geometry.camera_poses.empty();
  const std::map<std::string, ImageFigures> figures =
      fitted ? FiguresByPose(*report.bundle) : std::map<std::string, ImageFigures>();
  std::map<std::string, const calibration::ImageCameraPose*> cameras;
  if (report.motion_check && report.motion_check->ok) {
    for (const calibration::ImageCameraPose& c : report.motion_check->cameras) cameras[c.pose_id] = &c;
  }
  std::string csv = std::string(kImageResidualsHeader) + "\n";
  for (const PoseObservation& pose : observations.poses) {
    csv += CsvField(pose.id) + "," + PoseRoleName(pose.role) + "," + std::to_string(pose.dots_px.size());
    const auto f = figures.find(pose.id);
    const ImageFigures none;
    const ImageFigures& g = f == figures.end() ? none : f->second;
    if (fitted) {
      csv += "," + std::to_string(g.used) + "," + std::to_string(g.screened_out) + "," +
             (g.used > 0 ? Number(std::sqrt(g.sum2_px2 / g.used)) : "") + "," +
             (g.max_dot >= 0 ? Number(g.max_px) + "," + std::to_string(g.max_dot) : ",");
    } else {
      csv += ",,,,,";
    }
    const auto c = cameras.find(pose.id);
    if (c != cameras.end()) {
      csv += "," + Number(c->second->translation_error_m * 1e3) + "," + Number(c->second->rotation_error_rad * 180 / kPi);
    } else {
      csv += ",,";
    }
    csv += "\n";
  }
  return csv;
}

}  // namespace selfcal::report
