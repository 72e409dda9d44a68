// Progress reporting on stderr: "stage  42%  1.3 s". One Progress per long operation; updates
// are throttled to a few per second so that reporting never costs measurable time, and nothing
// is printed when quiet (the CLI's --quiet) or when the stage finishes before the first tick.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace quadlod {

class Progress {
 public:
  Progress(std::string stage, bool quiet)
      : stage_(std::move(stage)), quiet_(quiet), start_(Clock::now()), last_(start_) {}

  /// Reports `done` of `total` units; prints at most every 250 ms.
  void update(double done, double total) {
    if (quiet_) return;
    const auto now = Clock::now();
    if (now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    printed_ = true;
    const double pct = total > 0 ? 100.0 * done / total : 0.0;
    std::fprintf(stderr, "\r%-12s %5.1f%%  %6.1f s", stage_.c_str(), pct, elapsed());
    std::fflush(stderr);
  }

  /// Ends the line; prints a final line only if something was printed before, or `always`.
  void finish(const std::string& summary = {}, bool always = false) {
    if (quiet_ || (!printed_ && !always)) return;
    std::fprintf(stderr, "\r%-12s 100.0%%  %6.1f s%s%s\n", stage_.c_str(), elapsed(),
                 summary.empty() ? "" : "  ", summary.c_str());
  }

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  using Clock = std::chrono::steady_clock;
  std::string stage_;
  bool quiet_;
  bool printed_ = false;
  Clock::time_point start_, last_;
};

/// Wall-clock stopwatch for per-stage timings in reports.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace quadlod
