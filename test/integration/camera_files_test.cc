// Camera files on the command line (docs/camera-files.md): `detect --camera-file`, `calibrate --camera-file`
// replacing the observations' camera, `--write-camera-opencv` / `--write-camera-visp` of the calibrated
// intrinsics, every written file read back; bad files refused naming the file, with nothing written.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/camera_file.h"
#include "io/hand_eye_file.h"
#include "io/observations_file.h"
#include "io/robot_config.h"
#include "support/cli.h"
#include "support/sim_worlds.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunSelfcal;
using testing::RunSelfcalInSource;

const std::string kFrankaCamera = "test/data/visp-franka-eye-in-hand/franka_camera.xml";
const std::string kFrankaDetect =
    "detect --images 'test/data/visp-franka-eye-in-hand/franka_image-*.png' --poses "
    "'test/data/visp-franka-eye-in-hand/franka_pose_rPe_*.yaml' --detector chessboard --grid 9x6 ";

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Every intrinsic of `camera` against a report's intrinsics object, to `relative` (0: exact).
void ExpectReportCamera(const nlohmann::json& intrinsics, const CameraIntrinsics& camera, double relative,
                        const std::string& what) {
  const IntrinsicsVector values = IntrinsicsOf(camera);
  for (int k = 0; k < kNumIntrinsics; ++k) {
    const std::string unit = k == kFx || k == kCx || k == kCy ? "_px" : "";
    const double expected = intrinsics.at(IntrinsicName(k)).at("value" + unit).get<double>();
    EXPECT_NEAR(values[k], expected, relative * std::abs(expected)) << what << " " << IntrinsicName(k);
  }
}

// The ViSP Franka set as a user runs it with the data's own camera file: detect takes it instead of the
// --camera-* values, calibrate replaces the observations' camera with it again (saying so), estimates f_x
// and k1 with the hand-eye transform, and writes both camera formats, which read back as the report's
// calibrated intrinsics (the OpenCV file to the rounding of f_y = mu f_x, the ViSP file to its 1e-12). Freeing p1 and p2 as well
// gives a lens ViSP cannot hold: refused with exit 2 before anything is written, the OpenCV file included.
TEST(CameraFilesCli, FrankaCameraFileInCalibratedCameraOutInBothFormats) {
  const fs::path dir = FreshDir("camera_files", "franka");
  const std::string obs = (dir / "franka.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource(kFrankaDetect + "--camera-file " + kFrankaCamera + " --out " + obs, &output), 0) << output;
  Result<ObservationSet> set = io::LoadObservations(obs);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  Result<CameraIntrinsics> file = io::LoadCameraFile(fs::path(SELFCAL_SOURCE_DIR) / kFrankaCamera);
  ASSERT_TRUE(file.ok()) << file.status().ToString();
  EXPECT_EQ(IntrinsicsOf(set->camera), IntrinsicsOf(*file));

  const fs::path out = dir / "calibration";
  const std::string opencv = (dir / "franka_opencv.yaml").string(), visp = (dir / "franka_visp.xml").string();
  ASSERT_EQ(RunSelfcalInSource("calibrate " + obs + " --camera-file " + kFrankaCamera + " --free camera,fx,k1 --out " +
                                   out.string() + " --write-camera-opencv " + opencv + " --write-camera-visp " + visp,
                               &output),
            0)
      << output;
  EXPECT_NE(output.find("camera: the intrinsics of " + kFrankaCamera + " replace the observations' camera"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("free hand-eye parameters + f_x + k1,"), std::string::npos) << output;
  const nlohmann::json report = ReadJson(out / "report.json");
  EXPECT_EQ(report.at("input").at("camera_file").at("path"), kFrankaCamera);
  const nlohmann::json& intrinsics = report.at("methods").at("bundle").at("intrinsics");
  EXPECT_TRUE(intrinsics.at("k1").at("estimated").get<bool>());
  EXPECT_FALSE(intrinsics.at("cx").at("estimated").get<bool>());
  EXPECT_EQ(intrinsics.at("cx").at("value_px").get<double>(), file->cx_px);  // held: the file's, unchanged
  Result<CameraIntrinsics> written_opencv = io::LoadCameraFile(opencv);
  ASSERT_TRUE(written_opencv.ok()) << written_opencv.status().ToString();
  Result<CameraIntrinsics> written_visp = io::LoadCameraFile(visp);
  ASSERT_TRUE(written_visp.ok()) << written_visp.status().ToString();
  Result<io::HandEyeResult> hand_eye = io::LoadHandEye((out / "hand_eye.yaml").string());
  ASSERT_TRUE(hand_eye.ok()) << hand_eye.status().ToString();
  ASSERT_TRUE(hand_eye->camera.has_value());
  // The model's camera is the pose-noise solve's here (the residuals show a pose error, which it models):
  // all three equal the report's hand_eye.pose_noise.intrinsics.
  const nlohmann::json& noise = report.at("hand_eye").at("pose_noise");
  ASSERT_EQ(noise.at("noise_source"), "estimated") << noise.dump();
  const nlohmann::json& model = noise.at("intrinsics");
  EXPECT_TRUE(model.at("k1").at("estimated").get<bool>());
  ExpectReportCamera(model, *written_opencv, 1e-15, "OpenCV file");  // mu: f_y / f_x rounded once
  ExpectReportCamera(model, *written_visp, 1e-12, "ViSP file");
  ExpectReportCamera(model, *hand_eye->camera, 0.0, "hand_eye.yaml");
  EXPECT_EQ(hand_eye->intrinsics_stddev[kK1], model.at("k1").at("stddev").get<double>());
  EXPECT_TRUE(std::isnan(hand_eye->intrinsics_stddev[kCx]));

  const fs::path refused = dir / "refused";
  const std::string opencv2 = (dir / "lens_opencv.yaml").string(), visp2 = (dir / "lens_visp.xml").string();
  EXPECT_EQ(RunSelfcalInSource("calibrate " + obs + " --free camera,fx,k1,k2,p1,p2 --out " + refused.string() +
                                   " --write-camera-opencv " + opencv2 + " --write-camera-visp " + visp2,
                               &output),
            2)
      << output;
  EXPECT_NE(output.find("--write-camera-visp " + visp2), std::string::npos) << output;
  EXPECT_NE(output.find("ViSP's perspective model has one radial term"), std::string::npos) << output;
  EXPECT_NE(output.find("nothing was written"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(refused));
  EXPECT_FALSE(fs::exists(opencv2));
  EXPECT_FALSE(fs::exists(visp2));
  // The same lens written as OpenCV alone is fine, and its p1, p2 are the report's.
  ASSERT_EQ(RunSelfcalInSource("calibrate " + obs + " --free camera,fx,k1,k2,p1,p2 --out " + refused.string() +
                                   " --write-camera-opencv " + opencv2,
                               &output),
            0)
      << output;
  Result<CameraIntrinsics> lens = io::LoadCameraFile(opencv2);
  ASSERT_TRUE(lens.ok()) << lens.status().ToString();
  ExpectReportCamera(ReadJson(refused / "report.json").at("hand_eye").at("pose_noise").at("intrinsics"), *lens, 1e-15,
                     "lens");
  EXPECT_NE(lens->p1, 0.0);
}

// A joint-angle set whose file states a wrong camera (principal point 4 px off, no k2): --camera-file with
// the true lens replaces it, the held intrinsics are the file's exactly, and calibrated_model.yaml carries
// the calibrated camera and f_x's sigma as the report has them.
TEST(CameraFilesCli, CameraFileReplacesTheObservationsCameraOfAJointAngleSet) {
  const fs::path dir = FreshDir("camera_files", "puma");
  sim::SimOptions options;
  options.camera.k1 = -0.1;
  options.camera.k2 = 0.08;
  options.camera.p1 = 0.001;
  const sim::SimResult world = testing::PumaArcWorld(options);
  ObservationSet obs = world.observations;
  CameraIntrinsics truth = world.truth.camera_true;
  truth.fx_px = obs.camera.fx_px;  // the file holds the prior f_x; the bundle estimates it
  obs.camera.cx_px += 4.0;
  obs.camera.k2 = 0.0;
  const std::string obs_path = (dir / "obs.yaml").string(), camera_path = (dir / "camera.yaml").string();
  ASSERT_TRUE(io::SaveObservations(obs, obs_path).ok());
  ASSERT_TRUE(io::SaveCameraOpenCv(truth, camera_path).ok());
  const fs::path out = dir / "out";
  std::string output;
  ASSERT_EQ(RunSelfcal("calibrate " + obs_path + " --camera-file " + camera_path + " --out " + out.string(), &output), 0)
      << output;
  const nlohmann::json report = ReadJson(out / "report.json");
  const nlohmann::json& intrinsics = report.at("methods").at("bundle").at("intrinsics");
  CameraIntrinsics expected = truth;
  expected.fx_px = report.at("fx_px").get<double>();
  ExpectReportCamera(intrinsics, expected, 0.0, "report");
  EXPECT_NEAR(expected.fx_px, world.truth.camera_true.fx_px, 4 * report.at("methods").at("bundle").at("fx_stddev_px").get<double>());
  Result<io::CalibratedModel> model = io::LoadCalibratedModel((out / "calibrated_model.yaml").string());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_TRUE(model->camera.has_value());
  EXPECT_EQ(IntrinsicsOf(*model->camera), IntrinsicsOf(expected));
  EXPECT_EQ(model->intrinsics_stddev[kFx], intrinsics.at("fx").at("stddev_px").get<double>());
  EXPECT_TRUE(std::isnan(model->intrinsics_stddev[kK2]));
  EXPECT_EQ(report.at("input").at("camera_file").at("sha256").get<std::string>().size(), 64u);
}

// `--fix fx` with a camera file holds the file's f_x to the bit in every solve, stated as held (never
// `+- nan`): on the ViSP Franka set (flange poses, whose start from the flat board's images gives another
// f_x) in hand_eye.yaml and report.json, and on a joint-angle set (the paper pipeline's f_x another start)
// in calibrated_model.yaml, where the observations file states an f_x 1 % off the file's.
TEST(CameraFilesCli, AHeldFocalLengthIsTheCameraFilesToTheBit) {
  const fs::path dir = FreshDir("camera_files", "held_fx");
  const std::string obs = (dir / "franka.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource(kFrankaDetect + "--camera-file " + kFrankaCamera + " --out " + obs, &output), 0) << output;
  Result<CameraIntrinsics> file = io::LoadCameraFile(fs::path(SELFCAL_SOURCE_DIR) / kFrankaCamera);
  ASSERT_TRUE(file.ok()) << file.status().ToString();
  const fs::path out = dir / "franka_cal";
  ASSERT_EQ(RunSelfcalInSource("calibrate " + obs + " --camera-file " + kFrankaCamera + " --fix fx --no-html --out " +
                                   out.string(),
                               &output),
            0)
      << output;
  EXPECT_EQ(output.find("nan"), std::string::npos) << output;
  EXPECT_NE(output.find("f_x = 607.593 px (held)"), std::string::npos) << output;
  const nlohmann::json fx = ReadJson(out / "report.json").at("methods").at("bundle").at("intrinsics").at("fx");
  EXPECT_EQ(fx.at("value_px").get<double>(), file->fx_px);
  EXPECT_FALSE(fx.at("estimated").get<bool>());
  EXPECT_TRUE(fx.at("stddev_px").is_null());
  Result<io::HandEyeResult> hand_eye = io::LoadHandEye((out / "hand_eye.yaml").string());
  ASSERT_TRUE(hand_eye.ok()) << hand_eye.status().ToString();
  ASSERT_TRUE(hand_eye->camera.has_value());
  EXPECT_EQ(hand_eye->camera->fx_px, file->fx_px);
  EXPECT_TRUE(std::isnan(hand_eye->intrinsics_stddev[kFx]));

  const sim::SimResult world = testing::PumaArcWorld(0.2);
  ObservationSet joints = world.observations;
  const CameraIntrinsics truth = world.truth.camera_true;
  joints.camera.fx_px = 1.01 * truth.fx_px;
  const std::string joints_path = (dir / "puma.yaml").string(), camera_path = (dir / "puma_camera.yaml").string();
  ASSERT_TRUE(io::SaveObservations(joints, joints_path).ok());
  ASSERT_TRUE(io::SaveCameraOpenCv(truth, camera_path).ok());
  Result<CameraIntrinsics> puma_file = io::LoadCameraFile(camera_path);
  ASSERT_TRUE(puma_file.ok()) << puma_file.status().ToString();
  const fs::path puma_out = dir / "puma_cal";
  ASSERT_EQ(RunSelfcal("calibrate " + joints_path + " --camera-file " + camera_path + " --fix fx --no-html --out " +
                           puma_out.string(),
                       &output),
            0)
      << output;
  EXPECT_EQ(output.find("nan"), std::string::npos) << output;
  EXPECT_NE(output.find(" px (held)"), std::string::npos) << output;
  Result<io::CalibratedModel> model = io::LoadCalibratedModel((puma_out / "calibrated_model.yaml").string());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_TRUE(model->camera.has_value());
  EXPECT_EQ(model->camera->fx_px, puma_file->fx_px);
  EXPECT_TRUE(std::isnan(model->intrinsics_stddev[kFx]));
}

// Bad camera files and options: exit 2, the message names the file (and what is wrong), nothing written.
TEST(CameraFilesCli, BadCameraFilesAreRefusedNamingTheFileAndNothingIsWritten) {
  const fs::path dir = FreshDir("camera_files", "bad");
  const sim::SimResult world = testing::PumaArcWorld(0.2);
  const std::string obs_path = (dir / "obs.yaml").string();
  ASSERT_TRUE(io::SaveObservations(world.observations, obs_path).ok());
  CameraIntrinsics other_size = world.observations.camera;
  other_size.width_px = 800;
  const std::string sized = (dir / "size.yaml").string(), unknown = (dir / "unknown.yaml").string();
  ASSERT_TRUE(io::SaveCameraOpenCv(other_size, sized).ok());
  ASSERT_TRUE(io::SaveCameraOpenCv(world.observations.camera, unknown).ok());
  std::ofstream(unknown, std::ios::app) << "focal_lenght: 1000.\n";
  const fs::path out = dir / "out";
  struct Case {
    std::string arguments, expected;
  };
  const Case cases[] = {
      {"calibrate " + obs_path + " --camera-file " + (dir / "missing.xml").string(), (dir / "missing.xml").string()},
      {"calibrate " + obs_path + " --camera-file " + unknown, "focal_lenght"},
      {"calibrate " + obs_path + " --camera-file " + sized, "camera file " + sized + " is for 800x480 images"},
      {"calibrate " + obs_path + " --camera-file " + unknown + " --camera-name Camera", "is an OpenCV file"},
      {"calibrate " + obs_path + " --camera-name Camera", "--camera-name Camera selects a camera of a --camera-file"},
  };
  std::string output;
  for (const Case& c : cases) {
    EXPECT_EQ(RunSelfcal(c.arguments + " --out " + out.string() + " --write-camera-opencv " + (dir / "w.yaml").string(),
                         &output),
              2)
        << c.arguments << "\n" << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.arguments << "\n" << output;
    EXPECT_FALSE(fs::exists(out)) << c.arguments;
    EXPECT_FALSE(fs::exists(dir / "w.yaml")) << c.arguments;
  }
  // detect: the file is refused before any image is read into a result, and the --camera-* values are
  // not taken beside it.
  const std::string detect = kFrankaDetect + "--out " + (dir / "franka.yaml").string() + " --camera-file ";
  EXPECT_EQ(RunSelfcalInSource(detect + unknown, &output), 2) << output;
  EXPECT_NE(output.find(unknown), std::string::npos) << output;
  EXPECT_EQ(RunSelfcalInSource(detect + kFrankaCamera + " --camera-fx-px 600", &output), 2) << output;
  EXPECT_NE(output.find("leave out --camera-fx-px"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcalInSource(detect + sized, &output), 2) << output;
  EXPECT_NE(output.find("camera file " + sized + " is for 800x480 images, the images are 640x480"), std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(dir / "franka.yaml"));
}

// An OpenCV camera file nested 100,000 deep crashed OpenCV's reader: selfcal survived (the reader runs in a
// child process) but answered exit 70 "internal error". A repeated key was taken (the last one). Both are
// now refusals (exit 2) naming the file and the line, with nothing written.
TEST(CameraFilesCli, DeeplyNestedOrRepeatedKeyOpenCvFilesAreRefusedByLine) {
  const fs::path dir = FreshDir("camera_files", "deep");
  const sim::SimResult world = testing::PumaArcWorld(0.2);
  const std::string obs_path = (dir / "obs.yaml").string(), good = (dir / "good.yaml").string();
  ASSERT_TRUE(io::SaveObservations(world.observations, obs_path).ok());
  ASSERT_TRUE(io::SaveCameraOpenCv(world.observations.camera, good).ok());
  const std::string text = testing::ReadFile(good);
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  std::string nested = text + "nested: ";
  for (int i = 0; i < 100000; ++i) nested += "[";
  for (int i = 0; i < 100000; ++i) nested += "]";
  std::ofstream(dir / "deep.yaml") << nested << "\n";
  std::ofstream(dir / "repeated.yaml") << text << "image_width: 800\n";
  const fs::path out = dir / "out";
  for (const auto& [file, expected] :
       {std::pair<std::string, std::string>{"deep.yaml", "YAML nested deeper than 64 levels at "},
        {"repeated.yaml", "duplicate key `image_width` at "}}) {
    const std::string path = (dir / file).string();
    std::string output;
    EXPECT_EQ(RunSelfcal("calibrate " + obs_path + " --camera-file " + path + " --out " + out.string(), &output), 2)
        << file << "\n" << output;
    EXPECT_NE(output.find(expected + path + ":" + std::to_string(lines + 1)), std::string::npos) << file << "\n" << output;
    EXPECT_EQ(output.find("internal error"), std::string::npos) << output;
    EXPECT_FALSE(fs::exists(out)) << file;
  }
}

// `selfcal` loads OpenCV and ViSP only for a camera file (libselfcal_camera_formats.so in ../lib/selfcal or
// beside it): a copy without that library calibrates a set without camera files as the built one does, byte
// for byte, and refuses a camera file to read or write naming where it looked for the library, with exit 70
// and before anything is written.
TEST(CameraFilesCli, SelfcalLoadsTheCameraFormatsOnlyForACameraFile) {
  const fs::path dir = FreshDir("camera_files", "lone");
  const sim::SimResult world = testing::PumaArcWorld(0.2);
  const std::string obs_path = (dir / "obs.yaml").string(), camera = (dir / "camera.yaml").string();
  ASSERT_TRUE(io::SaveObservations(world.observations, obs_path).ok());
  ASSERT_TRUE(io::SaveCameraOpenCv(world.observations.camera, camera).ok());
  const fs::path lone = dir / "selfcal";
  fs::copy_file(SELFCAL_BINARY, lone);
  std::string output;
  const std::string calibrate = " calibrate " + obs_path + " --no-html --quiet --out ";
  ASSERT_EQ(testing::RunBinary(lone.string(), calibrate + (dir / "lone").string(), &output), 0) << output;
  ASSERT_EQ(RunSelfcal(calibrate + (dir / "built").string(), &output), 0) << output;
  for (const char* name : {"calibrated_model.yaml", "calibrated.urdf"}) {
    std::ifstream a(dir / "lone" / name), b(dir / "built" / name);
    std::stringstream text_a, text_b;
    text_a << a.rdbuf();
    text_b << b.rdbuf();
    EXPECT_EQ(text_a.str(), text_b.str()) << name;
  }
  // Not found where an installed or a build-tree selfcal would have it: both places named.
  const fs::path installed = (dir / ".." / "lib" / "selfcal" / "libselfcal_camera_formats.so").lexically_normal();
  const std::string searched = "libselfcal_camera_formats.so, which was not found (searched " + installed.string() +
                               ", " + (dir / "libselfcal_camera_formats.so").string() + ")";
  const std::string cases[] = {" --camera-file " + camera, " --write-camera-opencv " + (dir / "w.yaml").string(),
                               " --write-camera-visp " + (dir / "w.xml").string()};
  for (const std::string& c : cases) {
    EXPECT_EQ(testing::RunBinary(lone.string(), calibrate + (dir / "out").string() + c, &output), 70) << c << output;
    EXPECT_NE(output.find(searched), std::string::npos) << c << "\n" << output;
    EXPECT_FALSE(fs::exists(dir / "out")) << c;
  }
  EXPECT_FALSE(fs::exists(dir / "w.yaml"));
  EXPECT_FALSE(fs::exists(dir / "w.xml"));
}

}  // namespace
}  // namespace selfcal
