// Observations files: what a calibration consumes (observations/observation_set.h) in a form that other
// tools can write. The format is specified in docs/observations-format.md:
//
//   format: selfcal-observations
//   version: 1
//   robot: {...keys of a robot config...}     # or robot_file: path (relative to this file)
//   camera: {width_px: 640, height_px: 480, fx_px: 1000.0, mu: 1.0, cx_px: 319.5, cy_px: 239.5, k1: 0.0}
//                                              # or camera_file: path (OpenCV or ViSP, io/camera_file.h)
//   pixel_noise_px: 0.2
//   yardsticks: [{dot_a: 3, dot_b: 17, length_mm: 250.0}]
//   check_distances: [{dot_a: 1, dot_b: 40, length_mm: 512.3}]    # optional, held out
//   poses:
//     - id: p00
//       role: identification                   # or verification; default identification
//       joints_deg: [0, -30, 120, 0, 45, 0]    # or joints_rad
//       dots: [[0, 312.25, 240.5], [1, 100.0, 20.0]]   # [dot id, u_px, v_px]
//
// Pixels: origin at the centre of the top-left pixel, u right, v down.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "io/yaml_schema.h"
#include "yaml/yaml_reader.h"
#include "observations/observation_set.h"

namespace selfcal::io {

inline constexpr const char* kObservationsFormat = "selfcal-observations";
inline constexpr int kObservationsVersion = 1;

// Reads and validates an observations file: schema (C1-C3), versions (P8), ObservationSet::Validate(),
// joint values in the plausible range and dots inside the image; joints outside the robot's limits are the
// controller's reading and kept (observations/joint_limits.h names them). Every problem is reported together
// (ErrorCode::kInvalidInput), naming the file, line and key.
Result<ObservationSet> LoadObservations(const std::string& path);

// The same for a document already parsed; robot_file is resolved relative to doc.path's directory. A pose's
// `base_from_flange` rotation is a recorded one (io/transform_yaml.h, kRecordedRotationTolerance): made a
// rotation when it is not one to 1e-12, and said in *notes (RotationCorrectionNote) when given.
Result<ObservationSet> ParseObservations(const yaml::YamlDocument& doc, std::vector<std::string>* notes = nullptr);

// Writes the set atomically (P4) in SI units (joints_rad, length_m, robot in exact form) with
// shortest round-trip numbers, so that LoadObservations returns a bit-identical set. Refuses a set
// that LoadObservations would refuse.
Status SaveObservations(const ObservationSet& set, const std::string& path);

// The required `camera` map of *root (width_px, height_px, fx_px, cx_px, cy_px, optional mu, k1, k2, p1, p2,
// k3), with the intrinsics' cross-field checks, or instead `camera_file: <path>` (relative to the file being
// read, io/camera_file.h; optional `camera_name` for a ViSP file); shared with the trajectory file's
// `planned_for` block.
bool ReadCamera(MapReader* root, Problems* problems, CameraIntrinsics* camera);

// The `camera` map as SaveObservations writes it, one line: k2, p1, p2, k3 only when non-zero.
std::string CameraYaml(const CameraIntrinsics& camera);

// The key of an intrinsic in a `camera` map: fx_px, mu, cx_px, cy_px, k1, k2, p1, p2, k3.
const char* IntrinsicYamlKey(int intrinsic);

// The standard deviations of the intrinsics as one line `{fx_px: 3.7, k1: 0.012}`, by the keys above, only
// the finite ones (held intrinsics have none); "" when none is finite.
std::string IntrinsicsStddevYaml(const IntrinsicsVector& stddev);

// The optional `intrinsics_stddev` map of *root (the keys above, each optional, >= 0) into *stddev (NaN
// where absent). Returns false when it is present and wrong (the problems recorded).
bool ReadIntrinsicsStddev(MapReader* root, IntrinsicsVector* stddev);

// The optional `camera` map of *root (a `camera_file` is not taken: files selfcal writes hold their
// camera), read as ReadCamera does; *camera untouched when absent. Returns false when present and wrong.
bool ReadOptionalCamera(MapReader* root, Problems* problems, std::optional<CameraIntrinsics>* camera);

}  // namespace selfcal::io
