// Usage errors in plain words: a mistyped subcommand or option gets the nearest known name
// (base/closest_name.h) instead of CLI11's "A subcommand is required".
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace selfcal::app {

// For a command line that did not parse: "selfcal: unknown command `calibrat`; did you mean `calibrate`?" or
// "selfcal calibrate: unknown option `--metod`; did you mean `--method`?", found by walking argv through
// the subcommands of `app`. "" when every word names a known command and option (CLI11's message is
// then the clearer one).
std::string UnknownNameMessage(const CLI::App& app, int argc, char** argv);

}  // namespace selfcal::app
