// Numbers on the command line, checked where CLI11 reads them, for every numeric option of every command
// (../shared/RELIABILITY.md C3): CLI11 2.1 converts an unsigned integer with strtoull, so `--seed -1` and
// `--seed 18446744073709551616` both became 18446744073709551615; `--seed 010` was octal 8; a floating
// option took `nan` and `inf`, which pass CLI11's Range check. One rule in one place: an option added
// later is covered without being named.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace selfcal::app {

// Adds to every option of `app` and of its subcommands (recursively) whose type CLI11 names INT or UINT
// (an integer or a list of them) a check that its value is a decimal integer, not negative and within
// 64 bits (leading zeros read as decimal, not octal), and to every FLOAT option a check that it is finite.
// A refusal is a CLI::ValidationError naming the option and the value ("--seed: -1 is negative: ..."), so
// the usage error exit of cli_main.h (2). Call after every option is added.
void CheckNumbersStrictly(CLI::App& app);

// The checks themselves, on one value as typed: "" when acceptable (the value rewritten to plain decimal
// where needed), else why not.
std::string CheckIntegerText(std::string& value);
std::string CheckFloatText(const std::string& value);

}  // namespace selfcal::app
