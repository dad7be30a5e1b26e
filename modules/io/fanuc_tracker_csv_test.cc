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

}  // namespace
}  // namespace selfcal::io
