#include "session/setup_file.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace selfcal::session
