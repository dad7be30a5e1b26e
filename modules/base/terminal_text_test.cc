#include "base/terminal_text.h"

#include <gtest/gtest.h>

#include <string>

namespace selfcal {
namespace {

using namespace std::string_literals;

TEST(TerminalSafe, EscapesNulAndTheClearScreenSequence) {
  EXPECT_EQ(TerminalSafe("ready\0tail"s), "ready\\x00tail");
  EXPECT_EQ(TerminalSafe("\x1b[2J\x1b[Hfault"), "\\x1b[2J\\x1b[Hfault");
  EXPECT_EQ(TerminalSafe("a\rb\x07" "c\x7f"), "a\\x0db\\x07c\\x7f");
}

TEST(TerminalSafe, KeepsPrintableTextTabsNewlinesAndUtf8) {
  const std::string text = "Schutzhalt: Achse 3 \xc2\xb1" "0.5\xc2\xb0\tok\n\xe6\xa9\x9f\xe6\xa2\xb0 \xf0\x9f\xa4\x96 a\\b";
  EXPECT_EQ(TerminalSafe(text), text);
}

TEST(TerminalSafe, EscapesC1ControlsAndInvalidUtf8) {
  EXPECT_EQ(TerminalSafe("x\xc2\x9b" "2Jy"), "x\\u009b2Jy");            // CSI as one C1 character
  EXPECT_EQ(TerminalSafe("\xff\xfe"), "\\xff\\xfe");                     // not UTF-8
  EXPECT_EQ(TerminalSafe("\xc3"), "\\xc3");                              // truncated sequence
  EXPECT_EQ(TerminalSafe("\xc0\xaf"), "\\xc0\\xaf");                     // overlong '/'
  EXPECT_EQ(TerminalSafe("\xed\xa0\x80"), "\\xed\\xa0\\x80");            // a surrogate
}

}  // namespace
}  // namespace selfcal
