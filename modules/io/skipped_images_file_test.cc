#include "io/skipped_images_file.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace selfcal::io {
namespace {

// What a YAML reader gets back is what was listed: ids that look like numbers or booleans stay strings, a
// reason with quotes, a colon and a line break survives, the counts are numbers.
TEST(SkippedImagesFile, ReadsBackAsListed) {
  SkippedImages list;
  list.observations = "out/obs.yaml";
  list.images = 5;
  list.kept = 3;
  list.skipped = {{"3", "images/3.png", "grid not identified (no_lattice): \"72\" dots\nsecond line"},
                  {"yes", "images/yes.png", "no point found"}};
  const YAML::Node root = YAML::Load(SkippedImagesText(list));
  EXPECT_EQ(root["format"].as<std::string>(), "selfcal-skipped-images");
  EXPECT_EQ(root["version"].as<int>(), 1);
  EXPECT_EQ(root["observations"].as<std::string>(), "out/obs.yaml");
  EXPECT_EQ(root["images"].as<int>(), 5);
  EXPECT_EQ(root["kept"].as<int>(), 3);
  ASSERT_EQ(root["skipped"].size(), 2u);
  EXPECT_EQ(root["skipped"][0]["pose"].as<std::string>(), "3");
  EXPECT_EQ(root["skipped"][0]["image"].as<std::string>(), "images/3.png");
  EXPECT_EQ(root["skipped"][0]["reason"].as<std::string>(), list.skipped[0].reason);
  EXPECT_EQ(root["skipped"][1]["pose"].as<std::string>(), "yes");
  EXPECT_EQ(root["skipped"][1]["pose"].Tag(), "!");  // quoted: a string, not YAML 1.1's boolean
}

TEST(SkippedImagesFile, NoneSkippedIsAnEmptyList) {
  SkippedImages list;
  list.observations = "obs.yaml";
  list.images = list.kept = 2;
  const YAML::Node root = YAML::Load(SkippedImagesText(list));
  ASSERT_TRUE(root["skipped"].IsSequence());
  EXPECT_EQ(root["skipped"].size(), 0u);
}

}  // namespace
}  // namespace selfcal::io
