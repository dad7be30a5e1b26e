#include "session/setup_file.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <iterator>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace selfcal::session {
namespace {

ObservationSet ASetup() {
  ObservationSet s;
  s.camera.width_px = 800;
  s.camera.height_px = 600;
  s.camera.fx_px = 1210.5;
  s.pixel_noise_px = 0.03;
  s.yardsticks = {{3, 10, 0.2}};
  s.check_distances = {{1, 2, 0.15}};
  return s;
}

TEST(SetupFile, EyeToHandRecordsItsFixedCameraExactly) {
  ObservationSet setup = ASetup();
  setup.robot.mount = CameraMount::kEyeToHand;
  setup.robot.base_from_cam = Rigid3(RotZ(0.3) * RotX(2.9) * RotY(-0.1), Eigen::Vector3d(0.9540123456789, -0.0512, 0.4762));
  const std::string text = SetupFileText(setup);
  ObservationSet back;
  ASSERT_TRUE(ParseSetupFile(text, "setup.json", &back).ok());
  EXPECT_EQ(back.robot.mount, CameraMount::kEyeToHand);
  EXPECT_EQ(back.robot.base_from_cam.rotation, setup.robot.base_from_cam.rotation);
  EXPECT_EQ(back.robot.base_from_cam.translation, setup.robot.base_from_cam.translation);
  // Eye-in-hand setups carry neither key, and read as eye-in-hand.
  const std::string old_text = SetupFileText(ASetup());
  EXPECT_EQ(old_text.find("configuration"), std::string::npos);
  ObservationSet plain;
  ASSERT_TRUE(ParseSetupFile(old_text, "setup.json", &plain).ok());
  EXPECT_EQ(plain.robot.mount, CameraMount::kEyeInHand);
}

TEST(SetupFile, ConfigurationRefusalsNameTheKeyAndLine) {
  ObservationSet setup = ASetup();
  setup.robot.mount = CameraMount::kEyeToHand;
  nlohmann::json j = nlohmann::json::parse(SetupFileText(setup));
  auto refusal = [](const nlohmann::json& value) {
    ObservationSet out;
    const Status s = ParseSetupFile(value.dump(2), "s/inputs/setup.json", &out);
    EXPECT_FALSE(s.ok());
    return s.message();
  };
  nlohmann::json missing = j;
  missing.erase("base_from_cam");
  EXPECT_NE(refusal(missing).find("base_from_cam"), std::string::npos) << refusal(missing);
  nlohmann::json other = j;
  other["configuration"] = "eye_on_base";
  EXPECT_NE(refusal(other).find("eye_on_base"), std::string::npos);
  nlohmann::json reflection = j;
  reflection["base_from_cam"]["rotation"][0] = {-1, 0, 0};
  EXPECT_NE(refusal(reflection).find("not a rotation"), std::string::npos) << refusal(reflection);
  nlohmann::json far = j;  // mm typed as m: a camera 1200 m from the base
  far["base_from_cam"]["translation_m"][2] = 1200.0;
  EXPECT_NE(refusal(far).find("`base_from_cam.translation_m` 1200 m is beyond the 10 m"), std::string::npos)
      << refusal(far);
  nlohmann::json in_hand = j;
  in_hand["configuration"] = "eye_in_hand";
  const std::string message = refusal(in_hand);
  EXPECT_NE(message.find("s/inputs/setup.json:"), std::string::npos) << message;
  EXPECT_NE(message.find("needs `configuration` eye_to_hand"), std::string::npos) << message;
}

TEST(SetupFile, NamingKeysRoundTripAndAreOptional) {
  SetupNaming naming;
  naming.reference_dots = {{3, 120.25, 40.5, 96.0}, {10, 300.125, 200.0, 88.5}};
  naming.reference_image = "/dev/video0";
  const std::string text = SetupFileText(ASetup(), naming);
  ObservationSet back;
  SetupNaming naming_back;
  ASSERT_TRUE(ParseSetupFile(text, "setup.json", &back, &naming_back).ok());
  ASSERT_EQ(naming_back.reference_dots.size(), 2u);
  EXPECT_EQ(naming_back.reference_dots[1].id, 10);
  EXPECT_EQ(naming_back.reference_dots[1].u_px, 300.125);
  EXPECT_EQ(naming_back.reference_dots[0].area_px2, 96.0);
  EXPECT_EQ(naming_back.reference_image, "/dev/video0");
  EXPECT_EQ(back.yardsticks[0].dot_b, 10);
  // A reader that does not ask for the naming keys reads the same file (version 1 unchanged)...
  ObservationSet plain;
  ASSERT_TRUE(ParseSetupFile(text, "setup.json", &plain).ok());
  EXPECT_EQ(plain.camera.fx_px, 1210.5);
  // ...and a setup without them is written exactly as before (no new keys), and reads with none.
  const std::string old_text = SetupFileText(ASetup());
  EXPECT_EQ(old_text.find("reference"), std::string::npos);
  SetupNaming none;
  ASSERT_TRUE(ParseSetupFile(old_text, "setup.json", &plain, &none).ok());
  EXPECT_TRUE(none.reference_dots.empty());
}

TEST(SetupFile, RepeatedReferenceIdIsRefusedNamingTheFile) {
  SetupNaming naming;
  naming.reference_dots = {{3, 1, 2, 3}, {3, 4, 5, 6}};
  ObservationSet back;
  SetupNaming naming_back;
  const Status s = ParseSetupFile(SetupFileText(ASetup(), naming), "cell/setup.json", &back, &naming_back);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(s.message().find("cell/setup.json"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("id 3"), std::string::npos) << s.message();
}

// The line (from 1) of the first `"key":` at or after the first `after` in `text`.
int LineOf(const std::string& text, const std::string& key, const std::string& after = "") {
  const size_t from = after.empty() ? 0 : text.find("\"" + after + "\":");
  const size_t at = text.find("\"" + key + "\":", from);
  EXPECT_NE(at, std::string::npos) << key;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

// Issue 16: setup.json's refusals named the key but never the line, and showed nlohmann's exception text
// ("[json.exception.out_of_range.403] key 'camera' not found"); each names file and line now.
TEST(SetupFile, EveryRefusalNamesTheFileAndTheLineOfItsKey) {
  struct Case {
    std::function<void(nlohmann::json&)> change;
    std::string key, after;
    int offset;  // lines after the key's: a missing key is named at its object's `{`
    std::string expected;
  };
  const std::vector<Case> cases = {
      {[](auto& j) { j["camera"]["fx_px"] = "big"; }, "fx_px", "", 0, "`camera.fx_px` must be a finite number (found string)"},
      {[](auto& j) { j["camera"].erase("k1"); }, "camera", "", 0, "missing key `k1` in `camera`"},
      {[](auto& j) { j["yardsticks"][0]["dot_a"] = 1.5; }, "dot_a", "yardsticks", 0,
       "`yardsticks[0].dot_a` must be an integer in [-2147483648, 2147483647] (found number)"},
      {[](auto& j) { j["check_distances"][0].erase("length_m"); }, "dot_a", "check_distances", -1,
       "missing key `length_m` in `check_distances[0]`"},
      {[](auto& j) { j["pixel_noise_px"] = -1; }, "pixel_noise_px", "", 0, "`pixel_noise_px` must be positive"},
      {[](auto& j) { j["camera"]["width_px"] = 0; }, "width_px", "", 0, "`camera.width_px` must be positive"},
      {[](auto& j) { j["version"] = 2; }, "version", "", 0, "format must be selfcal-session-setup version 1"},
      {[](auto& j) { j["camera"] = 5; }, "camera", "", 0, "`camera` must be an object (found number)"},
      // Issue 36: a key no version of the format has (a typo, a unit swapped) was ignored.
      {[](auto& j) { j["pixel_noise_pxs"] = 0.5; }, "pixel_noise_pxs", "", 0, "unknown key `pixel_noise_pxs`"},
      {[](auto& j) { j["camera"]["k2"] = 0.1; }, "k2", "", 0, "unknown key `k2` in `camera`"},
      {[](auto& j) { j["yardsticks"][0]["length_mm"] = 200; }, "length_mm", "", 0,
       "unknown key `length_mm` in `yardsticks[0]`"},
      // Issue 36: a check distance of 1e-300 m (the mutation campaign's) was taken: no two dots are that close.
      {[](auto& j) { j["check_distances"][0]["length_m"] = 1e-300; }, "length_m", "check_distances", 0,
       "`check_distances[0].length_m` = 1e-300 m is out of range: must be in [0.001, 100] m (two dots' centres, at "
       "least 1 mm apart)"},
      {[](auto& j) { j["yardsticks"][0]["length_m"] = 0.0009; }, "length_m", "yardsticks", 0,
       "`yardsticks[0].length_m` = 0.0009 m is out of range: must be in [0.001, 100] m (two dots' centres, at least 1 "
       "mm apart)"},
      {[](auto& j) { j["yardsticks"][0]["length_m"] = 250; }, "length_m", "yardsticks", 0,
       "`yardsticks[0].length_m` = 250 m is out of range: must be in [0.001, 100] m (two dots' centres, at least 1 mm "
       "apart)"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = nlohmann::json::parse(SetupFileText(ASetup()));
    c.change(j);
    const std::string text = j.dump(2);
    ObservationSet back;
    const Status s = ParseSetupFile(text, "cell/setup.json", &back);
    ASSERT_FALSE(s.ok()) << c.expected;
    EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
    EXPECT_EQ(s.message(), "cell/setup.json:" + std::to_string(LineOf(text, c.key, c.after) + c.offset) + ": " + c.expected);
  }
  // Not JSON, not an object: the line where nlohmann stopped, without its exception's text.
  ObservationSet back;
  const Status syntax = ParseSetupFile("{\n  \"format\": \"selfcal-session-setup\"\n  \"version\": 1\n}\n", "setup.json", &back);
  EXPECT_EQ(syntax.message().rfind("setup.json:3: not JSON: syntax error while parsing object", 0), 0u) << syntax.message();
  EXPECT_EQ(syntax.message().find("json.exception"), std::string::npos) << syntax.message();
  EXPECT_EQ(ParseSetupFile("\n[1, 2]", "setup.json", &back).message(),
            "setup.json:2: the document is not a JSON object (found array)");
  EXPECT_EQ(ParseSetupFile("", "setup.json", &back).message().rfind("setup.json:1: not JSON: ", 0), 0u);
}

// Issue 36: a key given twice in setup.json was taken, the last value (here another f_x) winning.
TEST(SetupFile, AKeyGivenTwiceIsRefusedNamingItsLines) {
  std::ifstream in(std::string(SELFCAL_SOURCE_DIR) + "/fuzz/regressions/setup/duplicate-key-camera-fx-px.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(text.empty());
  ObservationSet back;
  const Status s = ParseSetupFile(text, "cell/setup.json", &back);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(s.message(), "cell/setup.json:6: `camera.fx_px` is given twice (lines 5 and 6): a JSON reader would keep "
                         "one of them without a word; keep one");
}

}  // namespace
}  // namespace selfcal::session
