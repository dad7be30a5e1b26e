// Camera intrinsics files (OpenCV FileStorage, ViSP XML) and the observations file's lens keys.
#include <chrono>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <visp3/core/vpXmlParserCamera.h>

#include "io/camera_file.h"
#include "io/io_test_util.h"
#include "io/observations_file.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath

// Width, height, f_x, mu, c_x, c_y, k1, k2, p1, p2, k3; odd doubles: every bit must survive.
CameraIntrinsics Lens() {
  return CameraIntrinsics{1280,          720,    912.6 + 1.0 / 7.0, 1.0 - 1.0 / 1300.0, 641.3 + 1.0 / 3.0, 362.8 - 1.0 / 9.0,
                          0.1462,        -0.4667, 0.00061,          -0.00042,           0.4103};
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void ExpectSameCamera(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  EXPECT_EQ(a.width_px, b.width_px);
  EXPECT_EQ(a.height_px, b.height_px);
  const IntrinsicsVector va = IntrinsicsOf(a), vb = IntrinsicsOf(b);
  for (int i = 0; i < kNumIntrinsics; ++i) EXPECT_NEAR(va[i], vb[i], 1e-12 * std::max(1.0, std::abs(va[i]))) << IntrinsicName(i);
}

// vpXmlParserCamera::parse, ViSP's own reader (its chatter on std::cout silenced).
int VispParse(const std::string& path, const std::string& name, vpCameraParameters::vpCameraParametersProjType model,
              vpCameraParameters* cam, vpXmlParserCamera* parser) {
  std::ostringstream sink;
  std::streambuf* saved = std::cout.rdbuf(sink.rdbuf());
  const int code = parser->parse(*cam, path, name, model);
  std::cout.rdbuf(saved);
  return code;
}

TEST(CameraFile, OpenCvFileWrittenBySelfcalIsReadByOpenCv) {
  TempDir dir;
  const CameraIntrinsics cam = Lens();
  const std::string path = dir.File("camera.yaml");
  ASSERT_TRUE(SaveCameraOpenCv(cam, path).ok());
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat k, d;
  fs["camera_matrix"] >> k;
  fs["distortion_coefficients"] >> d;
  EXPECT_EQ(static_cast<int>(fs["image_width"]), 1280);
  EXPECT_EQ(static_cast<int>(fs["image_height"]), 720);
  ASSERT_EQ(k.rows, 3);
  ASSERT_EQ(k.cols, 3);
  ASSERT_EQ(d.total(), 5u);
  EXPECT_NEAR(k.at<double>(0, 0), cam.fx_px, 1e-12);
  EXPECT_NEAR(k.at<double>(1, 1), cam.fy_px(), 1e-12);
  EXPECT_NEAR(k.at<double>(0, 2), cam.cx_px, 1e-12);
  EXPECT_NEAR(k.at<double>(1, 2), cam.cy_px, 1e-12);
  EXPECT_EQ(k.at<double>(0, 1), 0.0);
  const double expected[5] = {cam.k1, cam.k2, cam.p1, cam.p2, cam.k3};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(d.at<double>(i), expected[i], 1e-12) << i;
  Result<CameraIntrinsics> back = LoadCameraFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ExpectSameCamera(cam, *back);
  EXPECT_TRUE(SameBits(back->fx_px, cam.fx_px));
}

TEST(CameraFile, VispFileWrittenBySelfcalIsReadByVisp) {
  TempDir dir;
  CameraIntrinsics cam = Lens();
  cam.k2 = cam.p1 = cam.p2 = cam.k3 = 0;
  const std::string path = dir.File("camera.xml");
  ASSERT_TRUE(SaveCameraVisp(cam, path, "D435").ok());
  vpCameraParameters visp;
  vpXmlParserCamera parser;
  ASSERT_EQ(VispParse(path, "D435", vpCameraParameters::perspectiveProjWithDistortion, &visp, &parser),
            vpXmlParserCamera::SEQUENCE_OK);
  EXPECT_EQ(parser.getWidth(), 1280u);
  EXPECT_EQ(parser.getHeight(), 720u);
  EXPECT_NEAR(visp.get_px(), cam.fx_px, 1e-12);
  EXPECT_NEAR(visp.get_py(), cam.fy_px(), 1e-12);
  EXPECT_NEAR(visp.get_u0(), cam.cx_px, 1e-12);
  EXPECT_NEAR(visp.get_v0(), cam.cy_px, 1e-12);
  EXPECT_NEAR(visp.get_kud(), cam.k1, 1e-12);
  // kdu: ViSP's approximate inverse, fitted; it undoes the distortion to well below a pixel at the corner.
  EXPECT_EQ(visp.get_kdu(), FitVispKdu(cam));
  const Eigen::Vector2d corner(-0.5, -0.5);
  const Eigen::Vector2d exact = PixelToNormalized(cam, cam.fx_px, corner);
  const Eigen::Vector2d xd = CenteredPixel(cam, corner) / cam.fx_px;
  const Eigen::Vector2d approx = xd * (1 + visp.get_kdu() * xd.squaredNorm());
  EXPECT_LT((approx - exact).norm() * cam.fx_px, 5.0);
  Result<CameraIntrinsics> back = LoadCameraFile(path, "D435");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ExpectSameCamera(cam, *back);
  // Without distortion: ViSP's other model, read back by ViSP too.
  cam.k1 = 0;
  const std::string plain = dir.File("plain.xml");
  ASSERT_TRUE(SaveCameraVisp(cam, plain).ok());
  vpXmlParserCamera parser2;
  ASSERT_EQ(VispParse(plain, "Camera", vpCameraParameters::perspectiveProjWithoutDistortion, &visp, &parser2),
            vpXmlParserCamera::SEQUENCE_OK);
  EXPECT_NEAR(visp.get_px(), cam.fx_px, 1e-12);
  EXPECT_NEAR(visp.get_py(), cam.fy_px(), 1e-12);
  back = LoadCameraFile(plain);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ExpectSameCamera(cam, *back);
}

TEST(CameraFile, TheFrankaSetsVispFileReadsAsVispReadsIt) {
  const std::string path = SourcePath("test/data/visp-franka-eye-in-hand/franka_camera.xml");
  Result<CameraIntrinsics> cam = LoadCameraFile(path);
  ASSERT_TRUE(cam.ok()) << cam.status().ToString();
  vpCameraParameters visp;
  vpXmlParserCamera parser;
  ASSERT_EQ(VispParse(path, "Camera", vpCameraParameters::perspectiveProjWithDistortion, &visp, &parser),
            vpXmlParserCamera::SEQUENCE_OK);
  EXPECT_EQ(cam->width_px, 640);
  EXPECT_EQ(cam->height_px, 480);
  EXPECT_EQ(cam->fx_px, visp.get_px());
  EXPECT_EQ(cam->fx_px, 607.5931396484375);
  EXPECT_NEAR(cam->fy_px(), visp.get_py(), 1e-12);
  EXPECT_EQ(cam->cx_px, visp.get_u0());
  EXPECT_EQ(cam->cy_px, visp.get_v0());
  EXPECT_EQ(cam->k1, 0.0);
  EXPECT_FALSE(cam->HasDistortion());
  EXPECT_TRUE(LoadCameraFile(path, "Camera").ok());
}

TEST(CameraFile, CalibrateCameraStyleFileWithItsExtraKeysLoads) {
  TempDir dir;
  const std::string path = dir.File("out_camera_data.yml");
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "calibration_time" << "Thu 01 Jan" << "nr_of_frames" << 25 << "image_width" << 640 << "image_height" << 480
       << "board_width" << 9 << "board_height" << 6 << "square_size" << 0.025 << "flags" << 0;
    fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << 598.2, 0, 322.7, 0, 606.4, 235.9, 0, 0, 1);
    fs << "distortion_coefficients" << (cv::Mat_<double>(5, 1) << -0.37, 0.18, -0.0013, 0.0021, -0.045);
    fs << "avg_reprojection_error" << 0.21;
  }
  Result<CameraIntrinsics> cam = LoadCameraFile(path);
  ASSERT_TRUE(cam.ok()) << cam.status().ToString();
  EXPECT_EQ(cam->fx_px, 598.2);
  EXPECT_NEAR(cam->fy_px(), 606.4, 1e-12);
  EXPECT_EQ(cam->p2, 0.0021);
  EXPECT_EQ(cam->k3, -0.045);
}

// Each bad file: refused with ErrorCode::kInvalidInput, the file and the reason named.
class BadCameraFiles : public ::testing::Test {
 protected:
  ::testing::AssertionResult Refused(const std::string& name, const std::string& text, const std::string& why,
                                     const std::string& camera_name = "") {
    const std::string path = dir_.File(name);
    WriteFile(path, text);
    const Result<CameraIntrinsics> cam = LoadCameraFile(path, camera_name);
    if (cam.ok()) return ::testing::AssertionFailure() << "accepted";
    const Status& s = cam.status();
    if (s.code() != ErrorCode::kInvalidInput || s.message().find(why) == std::string::npos ||
        s.message().find(path) == std::string::npos) {
      return ::testing::AssertionFailure() << "expected \"" << why << "\" and the path in: " << s.ToString();
    }
    return ::testing::AssertionSuccess();
  }
  std::string OpenCv(const std::string& extra, const std::string& matrix = "3, cols: 3, dt: d, data: [600, 0, 320, 0, 600, 240, 0, 0, 1]") {
    return "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n  {rows: " + matrix +
           "}\ndistortion_coefficients: !!opencv-matrix\n  {rows: 5, cols: 1, dt: d, data: [0.1, 0, 0, 0, 0]}\n" + extra;
  }
  std::string Visp(const std::string& model) {
    return "<?xml version=\"1.0\"?>\n<root>\n  <camera>\n    <name>A</name>\n    <image_width>640</image_width>\n"
           "    <image_height>480</image_height>\n    <model>\n" + model + "    </model>\n  </camera>\n</root>\n";
  }
  TempDir dir_;
};

TEST_F(BadCameraFiles, OpenCv) {
  ASSERT_TRUE(LoadCameraFile((WriteFile(dir_.File("good.yaml"), OpenCv("")), dir_.File("good.yaml"))).ok());
  // Issue 16: every refusal names the line (cv::FileStorage keeps none: io/opencv_lines.h finds the key's).
  EXPECT_TRUE(Refused("unknown.yaml", OpenCv("distortion_coeffs: 3\n"),
                      "unknown key `distortion_coeffs` at " + dir_.File("unknown.yaml") + ":9"));
  EXPECT_TRUE(Refused("unknown.yaml", OpenCv("distortion_coeffs: 3\n"), "did you mean `distortion_coefficients`?"));
  std::string missing = OpenCv("");
  missing.replace(missing.find("image_height: 480\n"), 18, "");
  EXPECT_TRUE(Refused("missing.yaml", missing, "missing key `image_height` in the document at " + dir_.File("missing.yaml") + ":3"));
  EXPECT_TRUE(Refused("size.yaml", OpenCv("", "2, cols: 3, dt: d, data: [600, 0, 320, 0, 600, 240]"),
                      "`camera_matrix` at " + dir_.File("size.yaml") + ":5 is 2x3, must be 3x3"));
  EXPECT_TRUE(Refused("centre.yaml", OpenCv("", "3, cols: 3, dt: d, data: [600, 0, 700, 0, 600, 240, 0, 0, 1]"),
                      "`camera_matrix` at " + dir_.File("centre.yaml") + ":5: cx_px = 700 must lie in [0, width]"));
  EXPECT_TRUE(Refused("skew.yaml", OpenCv("", "3, cols: 3, dt: d, data: [600, 0.5, 320, 0, 600, 240, 0, 0, 1]"),
                      "has skew 0.5"));
  std::string rational = OpenCv("");
  const std::string five = "{rows: 5, cols: 1, dt: d, data: [0.1, 0, 0, 0, 0]}";
  rational.replace(rational.find(five), five.size(), "{rows: 8, cols: 1, dt: d, data: [0.1, 0, 0, 0, 0, 0.2, 0, 0]}");
  EXPECT_TRUE(Refused("rational.yaml", rational, "OpenCV's rational (k4, k5, k6) model"));
  // Found by fuzz/camera_opencv_fuzzer (fuzz/regressions/camera_opencv/): rows x cols are checked before
  // cv::FileStorage allocates them, so a huge or mistyped size is refused, not a 10 GB allocation.
  EXPECT_TRUE(Refused("huge.yaml", OpenCv("", "100000, cols: 100000, dt: d, data: [1]"), "of at most 16 entries"));
  EXPECT_TRUE(Refused("cols.yaml", OpenCv("", "3, cols: x, dt: d, data: [600, 0, 320, 0, 600, 240, 0, 0, 1]"),
                      "with rows x cols values in data"));
  // Found by the fuzzer too: cv::FileStorage::open throws std::length_error (not cv::Exception) on this.
  EXPECT_TRUE(Refused("length.yaml", ReadFile(SourcePath("fuzz/regressions/camera_opencv/filestorage-open-throws-length-error.yaml")),
                      "cannot read"));
  // Found by the fuzzer: OpenCV 4.6's YAML reader never returns on this text (a malformed `%YAML` line
  // first): such a directive is refused before OpenCV reads the text.
  EXPECT_TRUE(Refused("hang.yaml", ReadFile(SourcePath("fuzz/regressions/camera_opencv/malformed-yaml-directive-hangs-opencv.yaml")),
                      dir_.File("hang.yaml") + ":1: the first line must be the directive `%YAML:1.0`"));
  // Then this one, found after that fix: a second `%YAML` directive (on line 2, after `---`).
  EXPECT_TRUE(Refused("second.yaml", ReadFile(SourcePath("fuzz/regressions/camera_opencv/second-yaml-directive-hangs-opencv.yaml")),
                      dir_.File("second.yaml") + ":2: a second `%YAML` directive inside the document"));
  ASSERT_TRUE(LoadCameraFile((WriteFile(dir_.File("standard.yaml"), "%YAML 1.2" + OpenCv("").substr(9)), dir_.File("standard.yaml"))).ok())
      << "the YAML standard's directive is not refused";
  EXPECT_TRUE(Refused("fisheye.yaml", OpenCv("fisheye_model: 1\n"), "`fisheye_model` at " + dir_.File("fisheye.yaml") + ":9 is set"));
  // A parse error: the line selfcal's strict YAML reader names (it reads the text before cv::FileStorage
  // does, for the nesting and repeated keys); an empty file: line 1.
  EXPECT_TRUE(Refused("garbage.yaml", "%YAML:1.0\n---\nimage_width: 5\nimage_height: [\n",
                      "cannot read " + dir_.File("garbage.yaml") + " as an OpenCV FileStorage file: malformed YAML at " +
                          dir_.File("garbage.yaml") + ":5: did not find expected node content"));
  EXPECT_TRUE(Refused("empty.yaml", "", dir_.File("empty.yaml") + ":1 (the file is empty"));
  EXPECT_TRUE(Refused("utf16.yaml", std::string("\xff\xfe" "a\0:\0", 6), dir_.File("utf16.yaml") + ":1: "));
  EXPECT_TRUE(Refused("named.yaml", OpenCv(""), "a camera name (`A`) is for ViSP files", "A"));
  EXPECT_TRUE(Refused("camera.txt", OpenCv(""), "unknown format"));
  const Result<CameraIntrinsics> none = LoadCameraFile(dir_.File("absent.yaml"));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(none.status().message().find(dir_.File("absent.yaml")), std::string::npos) << none.status().ToString();
}

// Found by the fuzzer after the two fixes above: a text on which OpenCV 4.6's YAML reader never returns,
// with no sign to refuse it by. The reader runs in a child process that is stopped at the time limit.
TEST_F(BadCameraFiles, AnOpenCvTextWhoseReaderNeverFinishesIsStoppedAndRefusedNamingTheFile) {
  const std::string path = dir_.File("hang3.yaml");
  WriteFile(path, ReadFile(SourcePath("fuzz/regressions/camera_opencv/reader-never-finishes-stopped-by-time-limit.yaml")));
  const auto start = std::chrono::steady_clock::now();
  const Result<CameraIntrinsics> cam = LoadCameraFile(path, "", std::chrono::milliseconds(500));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(cam.ok());
  EXPECT_EQ(cam.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(cam.status().message().find(path + ":1: OpenCV's reader did not finish the text within 0.5 s and was stopped"),
            std::string::npos) << cam.status().ToString();
  EXPECT_GE(seconds, 0.49);
  EXPECT_LT(seconds, 10.0);
  // The same limit leaves a good file's reading alone, to the bit.
  WriteFile(dir_.File("good.yaml"), OpenCv(""));
  const Result<CameraIntrinsics> good = LoadCameraFile(dir_.File("good.yaml"), "", std::chrono::milliseconds(500));
  const Result<CameraIntrinsics> here = ParseOpenCvCameraText(dir_.File("good.yaml"), OpenCv(""));
  ASSERT_TRUE(good.ok() && here.ok()) << (good.ok() ? here.status().ToString() : good.status().ToString());
  EXPECT_EQ(IntrinsicsOf(*good), IntrinsicsOf(*here));
  EXPECT_EQ(good->k1, 0.1);
}

TEST_F(BadCameraFiles, Visp) {
  const std::string model = "      <type>perspectiveProjWithoutDistortion</type>\n      <px>600</px>\n      <py>601</py>\n"
                            "      <u0>320</u0>\n      <v0>240</v0>\n";
  ASSERT_TRUE(LoadCameraFile((WriteFile(dir_.File("good.xml"), Visp(model)), dir_.File("good.xml"))).ok());
  EXPECT_TRUE(Refused("name.xml", Visp(model), "no camera named `B` in <root> at " + dir_.File("name.xml") + ":2 (cameras: `A`)", "B"));
  std::string typo = model;
  typo.replace(typo.find("<py>601</py>"), 12, "<pyy>601</pyy>");
  EXPECT_TRUE(Refused("typo.xml", Visp(typo), "unknown element <pyy> in <model> at " + dir_.File("typo.xml") + ":10; did you mean <py>?"));
  EXPECT_TRUE(Refused("typo.xml", Visp(typo), "missing element <py> in <model>"));
  std::string kb = model;
  kb.replace(kb.find("perspectiveProjWithoutDistortion"), 32, "ProjWithKannalaBrandtDistortion");
  EXPECT_TRUE(Refused("kb.xml", Visp(kb), "a Kannala-Brandt or other fisheye model is not selfcal's"));
  std::string text = model;
  text.replace(text.find("<u0>320</u0>"), 12, "<u0>3x0</u0>");
  EXPECT_TRUE(Refused("number.xml", Visp(text), "<u0> = `3x0` at " + dir_.File("number.xml") + ":11 is not a finite number"));
  std::string two = Visp(model);
  two.replace(two.find("</root>"), 7, "  <camera><name>C</name></camera>\n</root>");
  EXPECT_TRUE(Refused("two.xml", two, "holds several cameras (`A`, `C`); choose one by name (the second at " +
                                           dir_.File("two.xml") + ":15)"));
  EXPECT_TRUE(Refused("rot.xml", "<?xml version=\"1.0\"?>\n<rot></rot>\n",
                      "the root element <rot> at " + dir_.File("rot.xml") + ":2 is not <root>"));
  const std::string unclosed = Visp(model);
  EXPECT_TRUE(Refused("broken.xml", unclosed.substr(0, unclosed.find("</root>")), dir_.File("broken.xml") + ":2: element <root> is never closed"));
  EXPECT_TRUE(Refused("cut.xml", unclosed.substr(0, 64), "unterminated tag"));
  std::string nosize = Visp(model);
  nosize.replace(nosize.find("    <image_width>640</image_width>\n"), 35, "");
  EXPECT_TRUE(Refused("nosize.xml", nosize, "missing element <image_width> in <camera>"));
}

// Issue 36's campaign: lines of a ViSP file's comments swapped or repeated left `--` inside a comment and
// a comment's text between elements, and a misspelt XML declaration; ViSP's files have none of them.
TEST_F(BadCameraFiles, VispTextThatIsNotWellFormedXmlIsRefusedByLine) {
  const std::string model = "      <type>perspectiveProjWithoutDistortion</type>\n      <px>600</px>\n      <py>601</py>\n"
                            "      <u0>320</u0>\n      <v0>240</v0>\n";
  std::string dashes = Visp(model);
  dashes.replace(dashes.find("  <camera>"), 0, "  <!--a comment\n  <!--repeated-->\n");
  EXPECT_TRUE(Refused("dashes.xml", dashes, dir_.File("dashes.xml") + ":3: `--` inside a comment"));
  std::string stray = Visp(model);
  stray.replace(stray.find("    <image_width>"), 0, "   the vpXmlParserCamera class.-->\n");
  EXPECT_TRUE(Refused("stray.xml", stray, dir_.File("stray.xml") + ":5: text `the vpXmlParserCamera class.-->` between the elements of <camera>"));
  std::string declaration = Visp(model);
  declaration.replace(declaration.find("version"), 7, "versino");
  EXPECT_TRUE(Refused("declaration.xml", declaration, dir_.File("declaration.xml") + ":1: the XML declaration must begin `<?xml version=`"));
}

std::string Nested(const std::string& open, const std::string& close, int depth) {
  std::string text;
  for (int i = 0; i < depth; ++i) text += open;
  for (int i = 0; i < depth; ++i) text += close;
  return text;
}

const char* const kOpenCvXml =
    "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n<image_height>480</image_height>\n"
    "<camera_matrix type_id=\"opencv-matrix\">\n  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n"
    "  <data>600. 0. 320. 0. 600. 240. 0. 0. 1.</data></camera_matrix>\n"
    "<distortion_coefficients type_id=\"opencv-matrix\">\n  <rows>5</rows>\n  <cols>1</cols>\n  <dt>d</dt>\n"
    "  <data>0.1 0. 0. 0. 0.</data></distortion_coefficients>\n</opencv_storage>\n";

const char* const kOpenCvJson =
    "{\n    \"image_width\": 640,\n    \"image_height\": 480,\n    \"camera_matrix\": {\n"
    "        \"type_id\": \"opencv-matrix\",\n        \"rows\": 3,\n        \"cols\": 3,\n        \"dt\": \"d\",\n"
    "        \"data\": [ 600.0, 0.0, 320.0, 0.0, 600.0, 240.0, 0.0, 0.0, 1.0 ]\n    },\n    \"distortion_coefficients\": {\n"
    "        \"type_id\": \"opencv-matrix\",\n        \"rows\": 5,\n        \"cols\": 1,\n        \"dt\": \"d\",\n"
    "        \"data\": [ 0.1, 0.0, 0.0, 0.0, 0.0 ]\n    }\n}\n";

// 100,000 nested levels crashed OpenCV's reader (the child process ended by SIGSEGV: exit 70 "internal
// error"); ViSP files are read into a tree whose destruction recursed as deep. Each is refused by the
// depth limit before any parser sees the text, naming the file and the line, quickly.
TEST_F(BadCameraFiles, DeepNestingIsRefusedByLineBeforeAnyParserSeesIt) {
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(Refused("deep.yaml", OpenCv("") + "nested: " + Nested("[", "]", 100000) + "\n",
                      dir_.File("deep.yaml") + ":9"));
  EXPECT_TRUE(Refused("deep.yaml", OpenCv("") + "nested: " + Nested("[", "]", 100000) + "\n", "nested deeper than 64"));
  EXPECT_TRUE(Refused("block.yaml", OpenCv("") + "nested:\n" + Nested("- ", "", 100000) + "x\n", "nested deeper than 64"));
  std::string xml = kOpenCvXml;
  xml.insert(xml.find("</opencv_storage>"), Nested("<a>", "</a>", 100000));
  EXPECT_TRUE(Refused("deep.xml", xml, dir_.File("deep.xml") +
                                           ":15: elements nested deeper than 64 levels, the limit for an OpenCV camera file"));
  std::string visp = Visp("      <type>perspectiveProjWithoutDistortion</type>\n");
  visp.insert(visp.find("</root>"), Nested("<camera>", "</camera>", 100000));
  EXPECT_TRUE(Refused("deep_visp.xml", visp, dir_.File("deep_visp.xml") +
                                                 ":11: elements nested deeper than 64 levels, the limit for a ViSP camera file"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

// cv::FileStorage keeps the last of a repeated key: a camera file with two image widths was read with the
// second. Refused naming the key and its line, in YAML, JSON and XML; the same files without the repeat load.
TEST_F(BadCameraFiles, OpenCvRepeatedKeysAreRefusedByLine) {
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"good.xml", kOpenCvXml}, {"good.json", kOpenCvJson}}) {
    WriteFile(dir_.File(name), text);
    const Result<CameraIntrinsics> good = LoadCameraFile(dir_.File(name));
    ASSERT_TRUE(good.ok()) << good.status().ToString();
    EXPECT_EQ(good->width_px, 640);
    EXPECT_EQ(good->k1, 0.1);
  }
  EXPECT_TRUE(Refused("dup.yaml", OpenCv("image_width: 800\n"), "duplicate key `image_width` at " + dir_.File("dup.yaml") + ":9"));
  EXPECT_TRUE(Refused("dup.yaml", OpenCv("", "3, rows: 3, cols: 3, dt: d, data: [600, 0, 320, 0, 600, 240, 0, 0, 1]"),
                      "duplicate key `rows` at " + dir_.File("dup.yaml") + ":6"));
  std::string json = kOpenCvJson;
  json.insert(json.find("    \"camera_matrix\""), "    \"image_width\": 800,\n");
  EXPECT_TRUE(Refused("dup.json", json, "duplicate key `image_width` at " + dir_.File("dup.json") + ":4"));
  std::string xml = kOpenCvXml;
  xml.insert(xml.find("</opencv_storage>"), "<image_width>800</image_width>\n");
  EXPECT_TRUE(Refused("dup.xml", xml, dir_.File("dup.xml") + ":15: element <image_width> appears twice in <opencv_storage>"));
}

// ViSP's reader took an element inside <type> (its text around the element read as the type) and bytes
// that are not UTF-8: both refused by line.
TEST_F(BadCameraFiles, VispElementInsideAValueAndInvalidUtf8AreRefusedByLine) {
  const std::string model = "      <type>perspectiveProj<x/>WithoutDistortion</type>\n      <px>600</px>\n      <py>601</py>\n"
                            "      <u0>320</u0>\n      <v0>240</v0>\n";
  EXPECT_TRUE(Refused("inside.xml", Visp(model), "element <x> inside <type> at " + dir_.File("inside.xml") + ":8: <type> holds a value"));
  std::string px = model;
  px.replace(px.find("<x/>"), 4, "");
  px.replace(px.find("<px>600</px>"), 12, "<px>6<b>0</b>0</px>");
  EXPECT_TRUE(Refused("inside.xml", Visp(px), "element <b> inside <px> at " + dir_.File("inside.xml") + ":9"));
  std::string name = Visp(px);
  name.replace(name.find("<px>6<b>0</b>0</px>"), 19, "<px>600</px>");
  ASSERT_TRUE(LoadCameraFile((WriteFile(dir_.File("good.xml"), name), dir_.File("good.xml"))).ok());
  name.replace(name.find("<name>A</name>"), 14, "<name>A\xff</name>");
  EXPECT_TRUE(Refused("utf8.xml", name, dir_.File("utf8.xml") + ":4: invalid UTF-8 (a ViSP camera file must be UTF-8)", "A"));
}

TEST(CameraFile, VispRefusesWhatItCannotHoldAndWritesNothing) {
  TempDir dir;
  const std::string path = dir.File("camera.xml");
  const Status status = SaveCameraVisp(Lens(), path);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(status.message().find(path), std::string::npos);
  EXPECT_NE(status.message().find("ViSP's perspective model has one radial term"), std::string::npos) << status.message();
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(dir.List().empty());
}

TEST(CameraFile, ObservationsTakeLensTermsInlineOrACameraFile) {
  TempDir dir;
  std::filesystem::create_directory(dir.File("cams"));
  ASSERT_TRUE(SaveCameraOpenCv(Lens(), dir.File("cams/d435.yaml")).ok());
  const std::string head = "format: selfcal-observations\nversion: 1.1\n";
  const std::string tail =
      "pixel_noise_px: 0.3\nposes:\n  - id: \"1\"\n    base_from_flange: {xyz_m: [0, 0, 0.5], rotvec_rad: [0, 0, 0]}\n"
      "    dots: [[0, 312.25, 240.5]]\n";
  WriteFile(dir.File("by_file.yaml"), head + "camera_file: cams/d435.yaml\n" + tail);
  Result<ObservationSet> by_file = LoadObservations(dir.File("by_file.yaml"));
  ASSERT_TRUE(by_file.ok()) << by_file.status().ToString();
  ExpectSameCamera(by_file->camera, Lens());
  // Saved inline with the lens terms, and loaded back bit-identical.
  ASSERT_TRUE(SaveObservations(*by_file, dir.File("saved.yaml")).ok());
  EXPECT_NE(ReadFile(dir.File("saved.yaml")).find(", k2: -0.4667, p1: 0.00061, p2: -0.00042, k3: 0.4103}"), std::string::npos);
  Result<ObservationSet> saved = LoadObservations(dir.File("saved.yaml"));
  ASSERT_TRUE(saved.ok()) << saved.status().ToString();
  const IntrinsicsVector a = IntrinsicsOf(by_file->camera), b = IntrinsicsOf(saved->camera);
  for (int i = 0; i < kNumIntrinsics; ++i) EXPECT_TRUE(SameBits(a[i], b[i])) << IntrinsicName(i);
  // A k1-only camera is written as before: no k2, p1, p2, k3 keys.
  EXPECT_EQ(CameraYaml(CameraIntrinsics()), "{width_px: 640, height_px: 480, fx_px: 1000, mu: 1, cx_px: 319.5, cy_px: 239.5, k1: 0}");
  // Errors: both forms, a bad camera file (named with the key and line), a lens key misspelt.
  WriteFile(dir.File("both.yaml"), head + "camera_file: cams/d435.yaml\ncamera: {width_px: 640}\n" + tail);
  const Status both = LoadObservations(dir.File("both.yaml")).status();
  EXPECT_NE(both.message().find("give the intrinsics one way, not both"), std::string::npos) << both.ToString();
  WriteFile(dir.File("missing.yaml"), head + "camera_file: cams/none.yaml\n" + tail);
  const Status missing = LoadObservations(dir.File("missing.yaml")).status();
  EXPECT_EQ(missing.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(missing.message().find("`camera_file` at " + dir.File("missing.yaml") + ":3: cannot read camera file " +
                                   dir.File("cams/none.yaml")),
            std::string::npos)
      << missing.ToString();
  WriteFile(dir.File("typo.yaml"),
            head + "camera: {width_px: 640, height_px: 480, fx_px: 600, cx_px: 320, cy_px: 240, k4: 0.1}\n" + tail);
  const Status typo = LoadObservations(dir.File("typo.yaml")).status();
  EXPECT_NE(typo.message().find("unknown key `k4` in `camera`"), std::string::npos) << typo.ToString();
  EXPECT_NE(typo.message().find("did you mean `k"), std::string::npos) << typo.ToString();
}

}  // namespace
}  // namespace selfcal::io
