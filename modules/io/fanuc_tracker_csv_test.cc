#include "io/fanuc_tracker_csv.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace selfcal::io {
namespace {

TEST(FanucTrackerCsv, RefusesMalformedRowsWithFileAndLine) {
  const std::string path = (std::filesystem::temp_directory_path() / "selfcal_fanuc_bad.csv").string();
  {
    std::ofstream out(path);
    for (int i = 0; i < 21; ++i) out << "1.0 ";
    out << "\n1 2 3\n";
  }
  const auto rows = LoadFanucTrackerCsv(path);
  ASSERT_FALSE(rows.ok());
  EXPECT_NE(rows.status().message().find(path + ":2:"), std::string::npos) << rows.status().message();
  std::filesystem::remove(path);
}

// A row as in N1N2N3Jval.csv: three SMRs about 100 mm apart, six zeros, six joints.
std::string Row(const std::string& first_value) {
  return first_value + " 500 300  700 520 310  620 600 290  0 0 0 0 0 0  10 20 30 40 50 60\n";
}

std::string WriteCsv(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

// The mutation campaign's 1e308 and 1e23 in an SMR column made a row's reflectors collinear and
// identify-tracker ended with an internal error; the value is refused by file, line and column.
TEST(FanucTrackerCsv, RefusesAnSmrCoordinateBeyondTheTrackersRange) {
  for (const std::string value : {"1e308", "99999999999999999999999", "-2e5"}) {
    const std::string path = WriteCsv("selfcal_fanuc_huge.csv", Row("600") + Row(value));
    const auto rows = LoadFanucTrackerCsv(path);
    ASSERT_FALSE(rows.ok()) << value;
    EXPECT_NE(rows.status().message().find(path + ":2: column 1:"), std::string::npos) << rows.status().message();
    EXPECT_NE(rows.status().message().find("100 m"), std::string::npos) << rows.status().message();
    std::filesystem::remove(path);
  }
}

TEST(FanucTrackerCsv, RefusesARowWhoseReflectorsAreCollinear) {
  const std::string collinear = "0 0 0  100 0 0  200 0 0  0 0 0 0 0 0  10 20 30 40 50 60\n";
  const std::string path = WriteCsv("selfcal_fanuc_collinear.csv", Row("600") + "# comment\n" + collinear);
  const auto rows = LoadFanucTrackerCsv(path);
  ASSERT_FALSE(rows.ok());
  EXPECT_NE(rows.status().message().find(path + ":3: the three SMRs are collinear or coincident"), std::string::npos)
      << rows.status().message();
  std::filesystem::remove(path);
}

// A NUL byte inside a number ended strtod's reading: "600\0" "5" was read as 600 without a word.
TEST(FanucTrackerCsv, RefusesANulByteInsideANumber) {
  const std::string path = WriteCsv("selfcal_fanuc_nul.csv", Row("600") + Row(std::string("600\0" "5", 5)));
  const auto rows = LoadFanucTrackerCsv(path);
  ASSERT_FALSE(rows.ok());
  EXPECT_NE(rows.status().message().find(path + ":2: '600"), std::string::npos) << rows.status().message();
  std::filesystem::remove(path);
}

TEST(FanucTrackerCsv, NoDataRowsNamesTheLinesRead) {
  const std::string path = WriteCsv("selfcal_fanuc_empty.csv", "");
  const auto rows = LoadFanucTrackerCsv(path);
  ASSERT_FALSE(rows.ok());
  EXPECT_NE(rows.status().message().find(path + ":1: no data rows"), std::string::npos) << rows.status().message();
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace selfcal::io
