// Progress of the pipeline on stderr (issue 20, "progress that means something"): one line per
// finished stage, "[2/5] select  37%  0.01 s  (elapsed 0.41 s)  …". The percentage is the work
// done — triangle-equivalents removed so far of those the whole reduction removes — not a share of
// a time budget. A reduction in many passes would print dozens of lines a second, so a stage line
// is only printed once at least `min_gap` seconds passed since the last one; the final line
// always is.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

namespace quadlod {

class StageLog {
 public:
  /// Seconds since the log started; injectable so that the throttle is tested without a clock.
  using Clock = std::function<double()>;
  using Sink = std::function<void(const std::string& line)>;

  explicit StageLog(bool enabled, double min_gap = 0.25, Clock clock = {}, Sink sink = {})
      : enabled_(enabled), min_gap_(min_gap), clock_(std::move(clock)), sink_(std::move(sink)),
        start_(std::chrono::steady_clock::now()) {}

  /// The reduction runs from `from` to `to` triangle-equivalents.
  void set_span(double from, double to) {
    from_ = from;
    to_ = to;
  }
  /// Where the reduction stands. A round that overshoots the target and is re-aimed leaves more
  /// faces than the one before; the work shown never goes back (it is the furthest reached).
  void set_count(double now) {
    const double share = from_ > to_ ? std::clamp((from_ - now) / (from_ - to_), 0.0, 1.0) : 1.0;
    work_ = std::max(work_, share);
  }
  /// Percent of the work done, as printed.
  int percent() const { return int(work_ * 100.0); }

  /// Stage `index` of `last_stage` finished after `seconds`.
  void done(int index, const char* stage, double seconds, const std::string& detail = {}) {
    if (!enabled_) return;
    const double now = elapsed();
    if (index < last_stage && printed_ && now - last_ < min_gap_) return;
    printed_ = true;
    last_ = now;
    char head[128];
    std::snprintf(head, sizeof head, "[%d/%d] %-9s %3d%%  %7.2f s  (elapsed %.2f s)", index, last_stage, stage,
                  index == last_stage ? 100 : percent(), seconds, now);
    const std::string line = std::string(head) + (detail.empty() ? "" : "  ") + detail;
    if (sink_)
      sink_(line);
    else
      std::fprintf(stderr, "%s\n", line.c_str());
  }

  static constexpr int last_stage = 5;

 private:
  double elapsed() const {
    if (clock_) return clock_();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  bool enabled_;
  double min_gap_;
  Clock clock_;
  Sink sink_;
  std::chrono::steady_clock::time_point start_;
  double work_ = 0.0, last_ = 0.0, from_ = 0.0, to_ = 0.0;
  bool printed_ = false;
};

}  // namespace quadlod
