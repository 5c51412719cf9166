#pragma once
// Progress of a long task (frames rendered, report runs, simulation steps), always on stderr so
// that stdout (tables, --json) stays clean.

#include <chrono>
#include <string>

namespace cps::cli {

/// Reports done / total of a task on stderr.
///
/// On a terminal (isatty(stderr)) one line is redrawn in place, at most 10 times per second:
///   render funnel [##########..........] 150/301 frames  28.1 frames/s  about 5 s left
/// Otherwise (CI logs, files) a plain line is printed each time another 10 % is done, or after
/// 5 s without a line, and a last line when the task ends:
///   render funnel: 150/301 frames (50 %), 28.1 frames/s, about 5 s left
///
/// quiet_s (s, >= 0; typical 0, or 2 for tasks that are often short): nothing is printed until
/// the task has run this long, so short runs stay silent. Under --quiet (diagnostics.h) nothing
/// is printed at all. Rates and times are wall clock.
class Progress {
 public:
  /// label: what runs ("render funnel"); total: units to do (>= 1); unit: their name, plural
  /// ("frames", "runs", "steps").
  Progress(std::string label, long long total, std::string unit, double quiet_s = 0.0);
  /// Ends the line if finish() was not called (e.g. on an error), so later messages start on a
  /// line of their own.
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Reports that `done` units (0..total) are finished. Cheap when nothing is printed (one clock
  /// read), so it can be called every step.
  void update(long long done);

  /// As update(done), with the time left (s, >= 0) estimated by the caller instead of from the
  /// rate of units so far: for a task whose units differ in cost (a report's runs, then their
  /// timed repeats). NaN: no estimate is printed. A later update(done) goes back to the rate.
  void update(long long done, double seconds_left);

  /// Reports the end: done = total, and the elapsed time.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  void advance(long long done);  // update's work once seconds_left_ is set
  void print(bool final_line);

  std::string label_;
  std::string unit_;
  long long total_;
  long long done_ = 0;
  double quiet_s_;
  bool terminal_;
  bool printed_ = false;   // something was printed
  bool line_open_ = false; // a terminal line without its newline yet
  bool finished_ = false;
  int next_decile_ = 1;
  double seconds_left_ = -1.0;  // the caller's estimate (update(done, s)); < 0: from the rate
  Clock::time_point start_;
  Clock::time_point last_print_;
};

}  // namespace cps::cli
