// One progress line on stderr, rewritten in place, on a terminal only: logs
// and pipes get a command's summary alone. Every command that can take more
// than a second shows one (docs/commands.md).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>

namespace impactlab::cli {

class ProgressLine {
 public:
  // Shown only when stderr is a terminal and not `quiet`; the clock starts here.
  explicit ProgressLine(bool quiet = false);
  ~ProgressLine();  // leaves no half line behind, whatever the command threw
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  bool Shown() const { return shown_; }
  double Seconds() const;  // since the start

  // "[3/8] 2.9 s, ~6.1 s left": `done` of `total` items of like cost, with
  // the time the rest will take at the pace so far; `left` says of what when
  // more work follows the items ("left to measure").
  std::string Count(std::size_t done, std::size_t total, std::string_view left = "left") const;

  void Show(const std::string& text);  // replaces the line
  void Clear();                        // before the summary or a warning

 private:
  bool shown_ = false;
  bool dirty_ = false;  // something is on the line
  std::chrono::steady_clock::time_point start_;
};

}  // namespace impactlab::cli
