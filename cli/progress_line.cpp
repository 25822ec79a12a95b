#include "cli/progress_line.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/format.h>

namespace impactlab::cli {
namespace {

// Seconds as a person reads them: tenths below 10 s (a "~0 s left" while a
// third of the work remains is no estimate), whole seconds above.
std::string SecondsText(double seconds) {
  return seconds < 10.0 ? fmt::format("{:.1f} s", seconds) : fmt::format("{:.0f} s", seconds);
}

}  // namespace

ProgressLine::ProgressLine(bool quiet)
    : shown_(!quiet && isatty(fileno(stderr)) != 0), start_(std::chrono::steady_clock::now()) {}

ProgressLine::~ProgressLine() { Clear(); }

double ProgressLine::Seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string ProgressLine::Count(std::size_t done, std::size_t total, std::string_view left) const {
  const double elapsed = Seconds();
  std::string text = fmt::format("[{}/{}] {}", done, total, SecondsText(elapsed));
  if (done > 0 && done < total) {
    const double rest = elapsed / static_cast<double>(done) * static_cast<double>(total - done);
    text += fmt::format(", ~{} {}", SecondsText(rest), left);
  }
  return text;
}

void ProgressLine::Show(const std::string& text) {
  if (!shown_) return;
  fmt::print(stderr, "\r\033[K{}", text);
  std::fflush(stderr);
  dirty_ = true;
}

void ProgressLine::Clear() {
  if (!shown_ || !dirty_) return;
  fmt::print(stderr, "\r\033[K");
  std::fflush(stderr);
  dirty_ = false;
}

}  // namespace impactlab::cli
