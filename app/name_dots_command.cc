// selfcal name-dots: one frame (camera or image file) -> detected dots named by the chosen identifier ->
// the annotated PNG (every dot's id drawn), a table of id, u, v, area, and the setup file's yardstick ids
// and reference dots (docs/real-hardware-quickstart.md). Writes the setup before any run hashes it.
#include <cstdio>
#include <iostream>
#include <memory>

#include <visp3/core/vpException.h>
#include <visp3/io/vpImageIo.h>
#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)
#include <visp3/core/vpDisplay.h>
#include <visp3/gui/vpDisplayX.h>
#endif

#include "acquisition/dot_naming.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/camera_options.h"
#include "app/commands.h"
#include "app/identify_options.h"
#include "base/atomic_file.h"
#include "io/plausible_limits.h"
#include "session/setup_file.h"

namespace selfcal::app {

namespace {

struct NameDotsSettings {
  std::string image;   // an image file, or...
  std::string device;  // ...a V4L2 camera, or...
  std::string camera;  // ...--camera aravis[:ID] (v4l2: --device)
  CameraMode mode;
  std::string setup;
  std::string out_png;
  bool show = false;
  std::vector<int> yardstick;
  double length_mm = 0;
  double fx_px = 0;           // a new setup's nominal f_x...
  double pixel_noise_px = 0;  // ...and centroid noise
  IdentifySettings identify;
};

Result<capture::Frame> GrabFrame(const NameDotsSettings& a) {
  capture::Frame frame;
  if (!a.image.empty()) {
    try {
      vpImageIo::read(frame.image, a.image);
    } catch (const vpException& e) {
      return Status::Error(ErrorCode::kInvalidInput, a.image + ": cannot read the image: " + e.getStringMessage());
    }
    if (frame.image.getSize() == 0) return Status::Error(ErrorCode::kInvalidInput, a.image + ": empty image");
    frame.source = a.image;
    return frame;
  }
  Result<std::unique_ptr<capture::FrameSource>> camera =
      MakeLiveCamera(a.camera == "aravis" ? "aravis" : "v4l2", a.device, a.mode);
  if (!camera.ok()) return camera.status();
  if (Status s = (*camera)->Open(); !s.ok()) return s;
  std::cout << "camera: " << (*camera)->Describe() << "\n";
  Result<capture::Frame> grabbed = (*camera)->Grab(capture::MonotonicNowS(), 2.0);
  (*camera)->Close();
  return grabbed;
}

// The setup to update (`text` empty: a new one, from the frame's size, --fx-px and --pixel-noise-px).
Status LoadOrStartSetup(const NameDotsSettings& a, const capture::Frame& frame, std::string* text,
                        ObservationSet* setup, session::SetupNaming* naming) {
  bool missing = false;
  Result<std::string> read = ReadFileCapped(a.setup, 1 << 20, &missing);
  if (missing) {
    if (!(a.fx_px > 0) || !(a.pixel_noise_px > 0)) {
      return Status::Error(ErrorCode::kInvalidInput, a.setup +
                                                         ": does not exist; to create it give the camera's nominal "
                                                         "--fx-px and the centroid noise --pixel-noise-px");
    }
    setup->camera.width_px = static_cast<int>(frame.image.getWidth());
    setup->camera.height_px = static_cast<int>(frame.image.getHeight());
    setup->camera.fx_px = a.fx_px;
    setup->camera.cx_px = 0.5 * (setup->camera.width_px - 1);
    setup->camera.cy_px = 0.5 * (setup->camera.height_px - 1);
    setup->pixel_noise_px = a.pixel_noise_px;
    return Status::Ok();
  }
  if (!read.ok()) return read.status();
  *text = *read;
  if (Status s = session::ParseSetupFile(*text, a.setup, setup, naming); !s.ok()) return s;
  if (setup->camera.width_px != static_cast<int>(frame.image.getWidth()) ||
      setup->camera.height_px != static_cast<int>(frame.image.getHeight())) {
    return Status::Error(ErrorCode::kInvalidInput, a.setup + ": camera is " + std::to_string(setup->camera.width_px) +
                                                       "x" + std::to_string(setup->camera.height_px) +
                                                       " px, the frame " + std::to_string(frame.image.getWidth()) +
                                                       "x" + std::to_string(frame.image.getHeight()));
  }
  return Status::Ok();
}

void PrintTable(const acquisition::NamingResult& r) {
  std::printf("%8s %10s %10s %10s\n", "id", "u_px", "v_px", "area_px2");
  for (const tracking::PreviousDot& d : r.named) {
    std::printf("%8d %10.2f %10.2f %10.1f\n", d.id, d.centroid_px.x(), d.centroid_px.y(), d.area_px2);
  }
  int unnamed = 0;
  for (int id : r.id_of_detection) unnamed += id < 0 ? 1 : 0;
  std::printf("%zu dots detected, %zu named, %d unnamed (drawn with '?')\n", r.detections.dots.size(), r.named.size(),
              unnamed);
}

void Show(const vpImage<vpRGBa>& annotated, const std::string& title) {
#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)
  vpImage<vpRGBa> shown = annotated;
  try {
    vpDisplayX display(shown, -1, -1, title);
    vpDisplay::display(shown);
    vpDisplay::displayText(shown, 15, 15, "click to close", vpColor::yellow);
    vpDisplay::flush(shown);
    vpDisplay::getClick(shown);
  } catch (const vpException& e) {
    std::cerr << "warning: cannot show the image (" << e.getStringMessage() << "); it is saved\n";
  }
#else
  (void)annotated;
  (void)title;
  std::cerr << "warning: this build has no X11 display; the image is saved\n";
#endif
}

int NameDotsFromSettings(const NameDotsSettings& a) {
  const int sources = (a.image.empty() ? 0 : 1) + (a.device.empty() ? 0 : 1) + (a.camera == "aravis" ? 1 : 0);
  if (sources != 1 || (a.camera == "v4l2" && a.device.empty())) {
    return Fail(Status::Error(ErrorCode::kInvalidInput,
                              "give exactly one of --image FILE, --device DEVICE (a V4L2 camera) and --camera "
                              "aravis[:ID]"));
  }
  if (!a.image.empty() && !a.mode.IsDefault()) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, "the camera options do not apply to --image " + a.image));
  }
  if (!a.yardstick.empty() && (a.yardstick.size() != 2 || !(a.length_mm >= io::kMinKnownDistanceM * 1e3) ||
                               !(a.length_mm <= io::kMaxKnownDistanceM * 1e3))) {
    return Fail(Status::Error(ErrorCode::kInvalidInput,
                              "--yardstick takes two dot ids A,B and needs --length-mm L, the distance between their "
                              "centres, in [1, 100000] mm"));
  }
  Result<capture::Frame> frame = GrabFrame(a);
  if (!frame.ok()) return Fail(frame.status());
  std::string setup_text;
  ObservationSet setup;
  session::SetupNaming naming;
  if (Status s = LoadOrStartSetup(a, *frame, &setup_text, &setup, &naming); !s.ok()) return Fail(s);
  auto identifier = MakeIdentifier(a.identify, "order", setup_text, a.setup);
  if (!identifier.ok()) return Fail(identifier.status());
  const acquisition::NamingResult named =
      acquisition::NameDots(*frame, identifier->get(), acquisition::RunOptions().detector);  // run's detector
  // The yardstick's ends are checked before anything is written: a refusal leaves the PNG and the setup as
  // they were (the table printed shows the ids named).
  const acquisition::YardstickChoice choice{a.yardstick.empty() ? -1 : a.yardstick[0],
                                            a.yardstick.empty() ? -1 : a.yardstick[1], a.length_mm * 1e-3};
  std::vector<std::string> warnings;
  if (!named.named.empty()) {
    if (Status s = acquisition::ApplyNaming(named, a.yardstick.empty() ? nullptr : &choice, frame->source, &setup,
                                            &naming, &warnings);
        !s.ok()) {
      PrintTable(named);
      return Fail(Status::Error(s.code(), s.message() + "; nothing written (" + a.setup + " and " + a.out_png +
                                              " left as they were; without --yardstick the image with every id drawn "
                                              "is written)"));
    }
  }
  const vpImage<vpRGBa> annotated = acquisition::AnnotateDots(frame->image, named);
  Result<std::string> png = acquisition::EncodeColourPng(annotated);
  if (!png.ok()) return Fail(png.status());
  if (Status s = WriteFileAtomically(a.out_png, *png); !s.ok()) return Fail(s);
  PrintTable(named);
  std::cout << "annotated image: " << a.out_png << "\n";
  if (a.show) Show(annotated, a.out_png);
  if (named.named.empty()) {
    return Fail(Status::Error(ErrorCode::kDegenerateData,
                              "no dot named: " + named.identifier_message + "; " + a.setup + " left unchanged"));
  }
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
  if (Status s = WriteFileAtomically(a.setup, session::SetupFileText(setup, naming)); !s.ok()) return Fail(s);
  std::cout << (setup_text.empty() ? "wrote " : "updated ") << a.setup << ": " << naming.reference_dots.size()
            << " reference dots";
  for (const KnownDistance& y : setup.yardsticks)
    std::cout << ", yardstick " << y.dot_a << "-" << y.dot_b << " " << y.length_m * 1e3 << " mm";
  std::cout << "\n";
  return 0;
}

}  // namespace

Command AddNameDotsCommand(CLI::App& app) {
  auto a = std::make_shared<NameDotsSettings>();
  CLI::App* cmd = app.add_subcommand(
      "name-dots",
      "Grab one frame, detect and name its dots, save it with every id drawn, set the yardstick in the setup");
  cmd->add_option("--image", a->image, "Name the dots of this image file (PNG, JPEG, PGM)");
  cmd->add_option("--device", a->device, "...or of one frame of this V4L2 camera (e.g. /dev/video0)");
  AddCameraOptions(cmd, &a->camera, &a->mode, {"v4l2", "aravis"});
  AddOutputOption(cmd, "--setup", &a->setup, OutputKind::kUpdatedFile,
                  "Setup file to write or update (docs/session-format.md; outside any session)")->required();
  AddOutputOption(cmd, "--out", &a->out_png, OutputKind::kFile, "Annotated PNG to write")->required();
  cmd->add_flag("--show", a->show, "Also show the annotated image in an X11 window (click to close)");
  cmd->add_option("--yardstick", a->yardstick, "The yardstick's two end dots A,B (ids as drawn)")->delimiter(',');
  cmd->add_option("--length-mm", a->length_mm, "The yardstick's length, mm (1 to 100000)")->check(CLI::PositiveNumber);
  cmd->add_option("--fx-px", a->fx_px, "New setup: the camera's nominal focal length, px")->check(CLI::PositiveNumber);
  cmd->add_option("--pixel-noise-px", a->pixel_noise_px, "New setup: the dot centroid noise, px")
      ->check(CLI::PositiveNumber);
  AddIdentifyOptions(cmd, &a->identify, "default: order");
  return [a]() { return NameDotsFromSettings(*a); };
}

}  // namespace selfcal::app
