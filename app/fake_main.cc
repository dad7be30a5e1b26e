#include "app/fake_main.h"

#include <signal.h>

#include "app/cli_numbers.h"
#include "app/exit_codes.h"

namespace selfcal::app {
namespace {

std::atomic<bool> g_stop{false};  // set by the signal handler only

std::atomic<int> g_acknowledgements{0};  // likewise

extern "C" void OnStopSignal(int) { g_stop.store(true); }
extern "C" void OnAcknowledgeSignal(int) { g_acknowledgements.fetch_add(1); }

void Handle(int signal, void (*handler)(int)) {
  struct sigaction action {};
  action.sa_handler = handler;
  sigemptyset(&action.sa_mask);
  ::sigaction(signal, &action, nullptr);
}

}  // namespace

std::optional<int> ParseFakeCommandLine(CLI::App& app, int argc, char** argv) {
  CheckNumbersStrictly(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kUsage);
  }
  return std::nullopt;
}

const std::atomic<bool>& StopOnSignals() {
  Handle(SIGINT, OnStopSignal);
  Handle(SIGTERM, OnStopSignal);
  return g_stop;
}

const std::atomic<int>& CountAcknowledgements() {
  Handle(SIGUSR1, OnAcknowledgeSignal);
  return g_acknowledgements;
}

}  // namespace selfcal::app
