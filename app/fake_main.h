// The start every loopback fake's main shares (selfcal-robot-sim, selfcal-ur-fake, selfcal-fanuc-fake): its
// command line parsed with every number checked strictly, and SIGINT / SIGTERM turned into a stop flag its
// Serve() polls.
#pragma once

#include <atomic>
#include <optional>

#include <CLI/CLI.hpp>

namespace selfcal::app {

// Parses `app` (numbers checked by CheckNumbersStrictly); nullopt to go on, else the code to exit with: 0
// after --help, the usage code on a bad command line (the message printed by CLI11).
std::optional<int> ParseFakeCommandLine(CLI::App& app, int argc, char** argv);

// From now on SIGINT and SIGTERM only set the returned flag (the fake then stops, exit 0).
const std::atomic<bool>& StopOnSignals();

// From now on each SIGUSR1 adds one to the returned count: a person's acknowledgement at the controller.
const std::atomic<int>& CountAcknowledgements();

}  // namespace selfcal::app
