// What a run keeps of a skipped pose and shows of every pose, through the selfcal binary: a jogged arm
// skips a pose (moved_after_settle), its rejected frame is on disk as a PNG that the skip record names,
// and calibrating the session gives the same result with or without those files; `--live-view on`
// without an X display is refused before anything is created, and `auto` runs without one.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"
#include "support/temp_files.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::RunSelfcal;

using testing::Contains;

// The JSON payloads of a session's journal, in order (J1 <length> <crc> <payload>).
std::vector<nlohmann::json> JournalRecords(const fs::path& session) {
  std::vector<nlohmann::json> records;
  std::istringstream lines(ReadFile((session / "journal.log").string()));
  for (std::string line; std::getline(lines, line);) {
    if (line.size() > 21) records.push_back(nlohmann::json::parse(line.substr(21)));
  }
  return records;
}

TEST(SkippedPoseFrames, AJoggedPoseKeepsItsRejectedFrameAndCalibrationIgnoresIt) {
  const fs::path dir = testing::FreshDir("skipped_frames", "jog");
  const fs::path session = dir / "s";
  // Move #3 (pose p03) is jogged 0.65 s after its arrival: after the 0.6 s settle, before the frame.
  std::string output;
  const std::string base = "run --session " + session.string() + " --seed 1 --live-view off";
  const int first = RunSelfcal(base + " --fault-jog-after-move 3 --fault-jog-delay-s 0.65", &output);
  ASSERT_EQ(first, 4) << output;  // the next move finds the arm away: halted
  EXPECT_TRUE(Contains(output, "pose p03 skipped: moved_after_settle")) << output;
  EXPECT_TRUE(Contains(output, "rejected frame(s) kept, first images/rejected/p03_0.png")) << output;
  // Continued without the fault (run.json then differs: the operator's override), the skip kept final.
  ASSERT_EQ(RunSelfcal(base + " --resume --revisit-skipped 0 --force-resume-with-changed-config", &output), 0)
      << output;

  const fs::path rejected = session / "images" / "rejected" / "p03_0.png";
  ASSERT_TRUE(fs::exists(rejected));
  const std::string png = ReadFile(rejected.string());
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  int skips = 0, frames_rejected = 0;
  for (const nlohmann::json& r : JournalRecords(session)) {
    if (r["type"] == "frame_rejected") {
      ++frames_rejected;
      EXPECT_EQ(r["image"], "images/rejected/p03_0.png");
      EXPECT_EQ(r["reason"], "moved_after_settle");
      EXPECT_EQ(r["bytes"], png.size());
    }
    if (r["type"] == "sample_skipped") {
      ++skips;
      EXPECT_EQ(r["pose"], 3);
      EXPECT_EQ(r["rejected_images"], nlohmann::json::array({"images/rejected/p03_0.png"}));
    }
  }
  EXPECT_EQ(skips, 1);
  EXPECT_EQ(frames_rejected, 1);

  // calibrate: the rejected frame is counted, never used; without the file the result is the same.
  ASSERT_EQ(RunSelfcal("calibrate " + session.string() + " --out " + (dir / "cal").string(), &output), 0) << output;
  EXPECT_TRUE(Contains(output, "1 frames of skipped poses in images/rejected/ (not used)")) << output;
  EXPECT_FALSE(Contains(output, "warning")) << output;
  fs::copy(session, dir / "without", fs::copy_options::recursive);
  fs::remove_all(dir / "without" / "images" / "rejected");
  ASSERT_EQ(RunSelfcal("calibrate " + (dir / "without").string() + " --out " + (dir / "cal2").string(), &output), 0)
      << output;
  nlohmann::json with = nlohmann::json::parse(ReadFile((dir / "cal" / "report.json").string()));
  nlohmann::json without = nlohmann::json::parse(ReadFile((dir / "cal2" / "report.json").string()));
  for (nlohmann::json* report : {&with, &without}) {
    report->erase("timing");
    report->erase("input");
    (*report)["session"].erase("path");
  }
  EXPECT_EQ(with, without);
  auto model_without_source = [](const fs::path& file) {  // the source line names the session's path
    std::string text = ReadFile(file.string());
    const size_t at = text.find("\nsource: ");
    return at == std::string::npos ? text : text.erase(at, text.find('\n', at + 1) - at);
  };
  const std::string model = model_without_source(dir / "cal" / "calibrated_model.yaml");
  EXPECT_TRUE(Contains(model, "\nparameters:"));
  EXPECT_EQ(model, model_without_source(dir / "cal2" / "calibrated_model.yaml"));
  fs::remove_all(dir);
}

TEST(SkippedPoseFrames, LiveViewOnWithoutADisplayIsRefusedBeforeAnythingIsCreated) {
  const fs::path dir = testing::FreshDir("skipped_frames", "live");
  std::string output;
  // Without $DISPLAY, whatever the developer's desktop has.
  const std::string no_display = "env -u DISPLAY " + std::string(SELFCAL_BINARY);
  EXPECT_EQ(testing::RunBinary(no_display, "run --session " + (dir / "s").string() + " --live-view on", &output), 2);
  EXPECT_TRUE(Contains(output, "--live-view on: $DISPLAY is not set")) << output;
  EXPECT_TRUE(Contains(output, "--live-view off")) << output;
  EXPECT_FALSE(fs::exists(dir / "s"));
  EXPECT_EQ(testing::RunBinary(no_display, "simulate --points --live-view on --out " + (dir / "o").string(), &output),
            2);
  EXPECT_TRUE(Contains(output, "--live-view on needs image mode")) << output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace selfcal
