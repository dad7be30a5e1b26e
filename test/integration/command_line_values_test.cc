// Values typed on the command line, checked where they are read (issue 36): every integer option of every
// command refuses a negative value and one beyond 64 bits, every floating option NaN and infinity, exit 2
// naming the option and the value. The options are taken from each command's own --help, so an option
// added later is tested without being listed here.
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.h"

namespace selfcal {
namespace {

using testing::RunSelfcal;

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The commands of `selfcal --help`.
std::vector<std::string> Commands() {
  std::string help;
  EXPECT_EQ(RunSelfcal("--help", &help), 0) << help;
  std::vector<std::string> commands;
  const std::regex line(R"(\n  ([a-z][a-z-]+) )");
  for (std::sregex_iterator it(help.begin(), help.end(), line), end; it != end; ++it) {
    commands.push_back((*it)[1]);
  }
  return commands;
}

// The options of `command` whose value CLI11 reads as an integer or a floating-point number, with "INT"
// (signed or not) or "FLOAT".
std::vector<std::pair<std::string, std::string>> NumericOptions(const std::string& command) {
  std::string help;
  EXPECT_EQ(RunSelfcal(command + " --help", &help), 0) << help;
  std::vector<std::pair<std::string, std::string>> options;
  const std::regex option(R"((--[a-z0-9-]+)(?:,[^ ]*)? (U?INT|FLOAT)\b)");
  for (std::sregex_iterator it(help.begin(), help.end(), option), end; it != end; ++it) {
    options.emplace_back((*it)[1], (*it)[2] == "FLOAT" ? "FLOAT" : "INT");
  }
  return options;
}

TEST(CommandLineValues, EveryNumericOptionOfEveryCommandRefusesWhatItCannotHold) {
  const std::vector<std::string> commands = Commands();
  ASSERT_GE(commands.size(), 10u);
  std::set<std::string> seen;
  int checked = 0;
  for (const std::string& command : commands) {
    for (const auto& [option, type] : NumericOptions(command)) {
      seen.insert(option);
      // One value each (a start of selfcal-full costs a fifth of a second); the other refusals below.
      const std::string value = type == "INT" ? "-1" : "nan";
      std::string output;
      EXPECT_EQ(RunSelfcal(command + " " + option + " " + value, &output), 2) << command << " " << option << " " << value
                                                                               << "\n" << output;
      EXPECT_TRUE(Has(output, option + ": " + value + " is n")) << command << " " << option << " " << value << "\n"
                                                               << output;
      ++checked;
    }
  }
  // The options the issue's campaign met, among them.
  for (const char* option : {"--seed", "--noise-px", "--gate-px", "--pool"}) EXPECT_EQ(seen.count(option), 1u) << option;
  EXPECT_GE(checked, 40);
}

// `--seed -1` and `--seed 18446744073709551616` both became 18446744073709551615 (CLI11 reads an unsigned
// integer with strtoull); `--seed 010` was octal 8.
TEST(CommandLineValues, ASeedIsADecimalIntegerWithin64Bits) {
  std::string output;
  EXPECT_EQ(RunSelfcal("simulate --points --seed -1 --out /nonexistent/x", &output), 2) << output;
  EXPECT_TRUE(Has(output, "--seed: -1 is negative")) << output;
  EXPECT_EQ(RunSelfcal("calibrate x.yaml --seed 18446744073709551616", &output), 2) << output;
  EXPECT_TRUE(Has(output, "--seed: 18446744073709551616 is larger than the largest integer an option takes")) << output;
  EXPECT_EQ(RunSelfcal("plan --seed 0x10 --robot r.yaml --out p.yaml", &output), 2) << output;
  EXPECT_TRUE(Has(output, "--seed: 0x10 is not a whole number in decimal digits")) << output;
  for (const char* value : {"inf", "-inf", "1e999"}) {
    EXPECT_EQ(RunSelfcal("simulate --points --noise-px=" + std::string(value), &output), 2) << output;
    EXPECT_TRUE(Has(output, "--noise-px: " + std::string(value) + " is not a finite number")) << output;
  }
  EXPECT_EQ(RunSelfcal("plan --pool 010 --check x.yaml --robot r.yaml", &output), 2) << output;
  EXPECT_FALSE(Has(output, "--pool")) << "010 is ten, inside --pool's range: " << output;
}

// `simulate --points --noise-px 10`, inside the range the option documents ([0, 10]), exited 2: the noise
// moved dots near the border out of the image and the observations file refused them. A detector reports
// no centre outside the image, so the simulator no longer does either. Without --points the option does
// not apply (image mode renders grey-level noise): refused.
TEST(CommandLineValues, SimulatePointsTakesEveryNoiseItsRangeDocuments) {
  const std::filesystem::path dir = testing::FreshDir("values", "noise");
  std::string output;
  const int code = RunSelfcal("simulate --points --noise-px 10 --seed 3 --out " + dir.string(), &output);
  EXPECT_NE(code, 2) << output;
  EXPECT_FALSE(Has(output, "lies outside the")) << output;
  EXPECT_TRUE(std::filesystem::exists(dir / "observations.yaml")) << output;
  EXPECT_EQ(RunSelfcal("simulate --noise-px 1 --out " + (dir / "image").string(), &output), 2) << output;
  EXPECT_TRUE(Has(output, "--noise-px needs --points")) << output;
  EXPECT_FALSE(std::filesystem::exists(dir / "image"));
  std::filesystem::remove_all(dir);
}

// `calibrate --free fx` exited 3 blaming the data ("insufficient excitation ... fixed here: " with an empty
// list, "f_x +- nan"): holding every kinematic parameter by request is no lack of excitation. It estimates
// f_x (and the dots) on the held model now; on a simulated robot whose kinematics differ from the nominal
// model, the held-out test refuses that model (exit 6). Holding everything leaves nothing to estimate: a
// usage error (exit 2).
TEST(CommandLineValues, CalibrateWithOnlyTheFocalLengthFreeSolvesIt) {
  const std::filesystem::path dir = testing::FreshDir("values", "free");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --seed 3 --out " + (dir / "sim").string(), &output), 0) << output;
  const std::string observations = (dir / "sim" / "observations.yaml").string();
  EXPECT_EQ(RunSelfcal("calibrate " + observations + " --free fx --out " + (dir / "fx").string(), &output), 6) << output;
  EXPECT_FALSE(Has(output, "insufficient excitation")) << output;
  EXPECT_FALSE(Has(output, "nan")) << output;
  EXPECT_TRUE(Has(output, "0 free kinematic parameters + f_x, 42 fixed (42 held by request)")) << output;
  EXPECT_TRUE(Has(output, "does not explain images it was not fitted to")) << output;
  EXPECT_EQ(RunSelfcal("calibrate " + observations + " --fix kinematics,camera,fx --out " + (dir / "none").string(),
                       &output), 2) << output;
  EXPECT_TRUE(Has(output, "nothing is left to estimate")) << output;
  std::filesystem::remove_all(dir);
}

// A default --help shows is a value the option takes: within its range and a number. `run --velocity-scaling`
// showed "[0.001 - 1]=-1" and `detect --camera-cx-px` "=nan", the "not given" sentinels of the code.
TEST(CommandLineValues, EveryDefaultShownInTheHelpIsAValueTheOptionTakes) {
  const std::regex ranged(R"((--[a-z0-9-]+) (?:U?INT|FLOAT):(?:U?INT|FLOAT) in \[([^ ]+) - ([^\]]+)\]=([^ \n]+))");
  const std::regex not_a_number(R"((--[a-z0-9-]+) [A-Z:]+[^=\n]*=(-?nan|-?inf)\b)");
  int ranges = 0;
  for (const std::string& command : Commands()) {
    std::string help;
    ASSERT_EQ(RunSelfcal(command + " --help", &help), 0) << help;
    for (std::sregex_iterator it(help.begin(), help.end(), ranged), end; it != end; ++it) {
      const std::string text = (*it)[4];
      char* rest = nullptr;
      const double shown = std::strtod(text.c_str(), &rest);
      EXPECT_TRUE(*rest == '\0' && shown >= std::stod((*it)[2]) && shown <= std::stod((*it)[3]))
          << command << " " << (*it)[0];
      ++ranges;
    }
    std::smatch found;
    EXPECT_FALSE(std::regex_search(help, found, not_a_number)) << command << " " << found[0];
  }
  EXPECT_GE(ranges, 20);
}

}  // namespace
}  // namespace selfcal
