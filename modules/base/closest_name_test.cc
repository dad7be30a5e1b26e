#include "base/closest_name.h"

#include <gtest/gtest.h>

namespace selfcal {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsSubstitutionsAndTranspositions) {
  EXPECT_EQ(EditDistance("", ""), 0);
  EXPECT_EQ(EditDistance("method", "method"), 0);
  EXPECT_EQ(EditDistance("metod", "method"), 1);        // insertion
  EXPECT_EQ(EditDistance("calibrate", "calibrat"), 1);  // deletion
  EXPECT_EQ(EditDistance("plan", "plen"), 1);           // substitution
  EXPECT_EQ(EditDistance("sutdy", "study"), 1);         // transposition
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
  EXPECT_EQ(EditDistance("", "run"), 3);
}

TEST(ClosestName, SuggestsTheNearestKnownName) {
  const std::vector<std::string> commands = {"calibrate", "simulate", "study", "plan", "run", "report", "detect"};
  EXPECT_EQ(ClosestName("calibrat", commands), "calibrate");
  EXPECT_EQ(ClosestName("simualte", commands), "simulate");
  EXPECT_EQ(ClosestName("rnu", commands), "run");
  EXPECT_EQ(ClosestName("cal", commands), "calibrate");  // an abbreviation
  EXPECT_EQ(ClosestName("method", {"out", "seed", "method", "fix"}), "method");
}

TEST(ClosestName, SaysNothingForAFarWord) {
  const std::vector<std::string> commands = {"calibrate", "simulate", "study", "plan", "run"};
  EXPECT_EQ(ClosestName("xyzzy", commands), "");
  EXPECT_EQ(ClosestName("banana", commands), "");
  EXPECT_EQ(ClosestName("q", commands), "");
}

}  // namespace
}  // namespace selfcal
