#include "report/terminal_progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace selfcal::report {

std::optional<double> EstimateRemainingSeconds(int64_t done, int64_t total, double elapsed_s) {
  if (total <= 0 || done <= 0 || !(elapsed_s >= 0)) return std::nullopt;
  if (done >= total) return 0.0;
  return elapsed_s * static_cast<double>(total - done) / static_cast<double>(done);
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "-:--";
  const auto s = static_cast<int64_t>(seconds);
  char buffer[32];
  if (s >= 3600) {
    std::snprintf(buffer, sizeof(buffer), "%lld:%02lld:%02lld", static_cast<long long>(s / 3600),
                  static_cast<long long>(s / 60 % 60), static_cast<long long>(s % 60));
  } else {
    std::snprintf(buffer, sizeof(buffer), "%lld:%02lld", static_cast<long long>(s / 60), static_cast<long long>(s % 60));
  }
  return buffer;
}

std::string ProgressText(int64_t done, int64_t total, double elapsed_s, int bar_width) {
  if (total <= 0) return std::to_string(done) + " done, " + FormatDuration(elapsed_s) + " elapsed";
  const double fraction = std::clamp(static_cast<double>(done) / static_cast<double>(total), 0.0, 1.0);
  const int filled = static_cast<int>(std::floor(fraction * bar_width));
  std::string text = "[" + std::string(filled, '#') + std::string(bar_width - filled, '.') + "] " +
                     std::to_string(done) + "/" + std::to_string(total) + " " + FormatDuration(elapsed_s) + " elapsed";
  const std::optional<double> left = EstimateRemainingSeconds(done, total, elapsed_s);
  text += left ? ", " + FormatDuration(std::ceil(*left)) + " left" : ", -:-- left";
  return text;
}

bool IsTerminal(int fd) { return isatty(fd) == 1; }

TerminalProgress::TerminalProgress(std::ostream& out, TerminalProgressOptions options)
    : out_(out), options_(std::move(options)) {}

TerminalProgress::~TerminalProgress() { Clear(); }

double TerminalProgress::Now() const {
  if (options_.now_s) return options_.now_s();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void TerminalProgress::Start(int64_t total, const std::string& label) {
  steps_.push_back({label, std::max<int64_t>(total, 0), 0, Now()});
  Draw();
}

void TerminalProgress::Advance(int64_t units) {
  if (steps_.empty()) return;
  Step& step = steps_.back();
  step.done += units;
  if (step.done == step.total || Now() - last_draw_s_ >= options_.min_redraw_s) Draw();
}

void TerminalProgress::Finish() {
  if (steps_.empty()) return;
  if (steps_.size() > 1) {
    steps_.pop_back();
    Draw();
    return;
  }
  // The outermost step ends with its last state on a line of its own.
  Draw();
  if (options_.enabled && drawn_) out_ << "\n" << std::flush;
  drawn_ = false;
  steps_.clear();
}

void TerminalProgress::Clear() {
  if (!options_.enabled || !drawn_) return;
  out_ << "\r\x1b[K" << std::flush;
  drawn_ = false;
}

void TerminalProgress::Draw() {
  if (!options_.enabled || steps_.empty()) return;
  const double now = Now();
  last_draw_s_ = now;
  std::string labels;
  for (size_t k = 0; k + 1 < steps_.size(); ++k) {
    const Step& s = steps_[k];
    labels += s.label + (s.total > 0 ? " " + std::to_string(s.done) + "/" + std::to_string(s.total) : "") + " > ";
  }
  const Step& inner = steps_.back();
  labels += inner.label + " ";
  const std::string figures = ProgressText(inner.done, inner.total, now - inner.start_s, options_.bar_width);
  // A narrow terminal loses the labels' end, never the figures.
  const int room = options_.width - static_cast<int>(figures.size());
  if (options_.width > 0 && static_cast<int>(labels.size()) > room) labels.resize(std::max(room, 0));
  out_ << "\r" << labels << figures << "\x1b[K" << std::flush;
  drawn_ = true;
}

}  // namespace selfcal::report
