#include "options/progress.h"

#include "options/diagnostics.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace cps::cli {
namespace {

constexpr double k_terminal_refresh_s = 0.1;  // redraw interval of the bar (s)
constexpr double k_log_interval_s = 5.0;      // longest silence between plain lines (s)
constexpr int k_bar_width = 24;               // characters

double seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// "42 s", "3 min 05 s", "1 h 02 min".
std::string duration_text(double s) {
  char buf[32];
  const long long t = static_cast<long long>(s + 0.5);
  if (t < 60) {
    std::snprintf(buf, sizeof buf, "%lld s", t);
  } else if (t < 3600) {
    std::snprintf(buf, sizeof buf, "%lld min %02lld s", t / 60, t % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lld h %02lld min", t / 3600, (t % 3600) / 60);
  }
  return buf;
}

}  // namespace

Progress::Progress(std::string label, long long total, std::string unit, double quiet_s)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(std::max(1LL, total)),
      quiet_s_(std::max(0.0, quiet_s)),
      terminal_(isatty(STDERR_FILENO) == 1),
      start_(Clock::now()),
      last_print_(start_) {}

Progress::~Progress() {
  if (line_open_) std::fputc('\n', stderr);
}

void Progress::update(long long done, double seconds_left) {
  seconds_left_ = std::isnan(seconds_left) ? std::nan("") : std::max(0.0, seconds_left);
  advance(done);
}

void Progress::update(long long done) {
  seconds_left_ = -1.0;  // from the rate
  advance(done);
}

void Progress::advance(long long done) {
  done_ = std::clamp(done, 0LL, total_);
  const Clock::time_point now = Clock::now();
  const double elapsed = seconds(now - start_);
  // The last unit is reported by finish(), with the elapsed time.
  if (elapsed < quiet_s_ || finished_ || done_ == total_) return;
  const double since = seconds(now - last_print_);
  bool due;
  if (terminal_) {
    due = !printed_ || since >= k_terminal_refresh_s;
  } else {
    const bool decile = done_ * 10 >= static_cast<long long>(next_decile_) * total_;
    due = decile || since >= k_log_interval_s || !printed_;
    if (decile) next_decile_ = static_cast<int>(done_ * 10 / total_) + 1;
  }
  if (!due) return;
  last_print_ = now;
  print(false);
}

void Progress::finish() {
  if (finished_) return;
  done_ = total_;
  const double elapsed = seconds(Clock::now() - start_);
  if (elapsed >= quiet_s_ || printed_) print(true);
  finished_ = true;
}

void Progress::print(bool final_line) {
  if (quiet()) return;
  const double elapsed = seconds(Clock::now() - start_);
  const double rate = elapsed > 0.0 ? static_cast<double>(done_) / elapsed : 0.0;
  const double left = seconds_left_ >= 0.0 || std::isnan(seconds_left_)
                          ? seconds_left_
                          : rate > 0.0 ? static_cast<double>(total_ - done_) / rate : 0.0;
  const int percent = static_cast<int>(100 * done_ / total_);
  char rate_text[48];
  std::snprintf(rate_text, sizeof rate_text, "%.*f %s/s", rate < 10.0 ? 2 : 1, rate, unit_.c_str());
  std::string tail = final_line ? "in " + duration_text(elapsed)
                     : done_ > 0 && !std::isnan(left) ? "about " + duration_text(left) + " left"
                                 : "";
  if (terminal_) {
    const int filled = static_cast<int>(k_bar_width * done_ / total_);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(k_bar_width - filled), '.');
    std::fprintf(stderr, "\r%s [%s] %lld/%lld %s  %s  %s\x1b[K", label_.c_str(), bar.c_str(),
                 done_, total_, unit_.c_str(), rate_text, tail.c_str());
    line_open_ = !final_line;
    if (final_line) std::fputc('\n', stderr);
  } else {
    std::fprintf(stderr, "%s: %lld/%lld %s (%d %%), %s%s%s\n", label_.c_str(), done_, total_,
                 unit_.c_str(), percent, rate_text, tail.empty() ? "" : ", ", tail.c_str());
  }
  std::fflush(stderr);
  printed_ = true;
}

}  // namespace cps::cli
