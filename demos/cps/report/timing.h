#pragma once
// How the report times a run: the clock (CPU time of the calling thread), the repeats and their
// quartiles, how many significant digits the spread of a time supports, and what the times were
// taken on (the machine, the compiler and its flags, the load).

#include <string>
#include <vector>

namespace cps::cli {

/// Timed repeats per run (`cps report --repeats`): the default, the quick sweep's default, and
/// the range accepted.
inline constexpr int kDefaultRepeats = 5;
inline constexpr int kQuickRepeats = 3;
constexpr int default_repeats(bool quick) { return quick ? kQuickRepeats : kDefaultRepeats; }
inline constexpr int kMinRepeats = 3;
inline constexpr int kMaxRepeats = 100;

/// The least CPU time (s) one timed repeat of a run should last: a run shorter than this (the
/// intersecting stack at 1 iteration is 30 steps, well under a millisecond) is stepped several
/// times over, each from its start, in one repeat, so that the clock's reading and the caches'
/// refill are a small part of what is measured. Runs of more than this are timed once a repeat.
inline constexpr double kMinRepeatSeconds = 0.02;

/// The CPU time (s) the calling thread has used (clock_gettime CLOCK_THREAD_CPUTIME_ID):
/// other processes on the machine, and other threads of this one, do not add to it, while
/// time in the kernel on its behalf does. Nanosecond resolution on Linux.
double thread_cpu_seconds();

/// The quartiles of a sample (its unit), by linear interpolation between order statistics
/// (Hyndman and Fan's type 7, numpy's default): for 5 values sorted x0..x4, q1 = x1, median = x2,
/// q3 = x3. All NaN for an empty sample.
struct Quartiles {
  double q1 = 0.0;
  double median = 0.0;
  double q3 = 0.0;
};
Quartiles quartiles(std::vector<double> samples);

/// The significant digits a time with quartiles q1 <= median <= q3 is printed with: one digit
/// past the first that the interquartile range leaves uncertain, floor(log10(median / (q3 -
/// q1))) + 2, in [2, 4] (a spread of 2.4 % of the median gives 3: 0.123). 3 when there is no
/// spread (q3 == q1, one value or equal values) or the numbers are not positive and finite.
int significant_digits(double q1, double median, double q3);

/// The digits for a ratio of two times with these relative spreads ((q3 - q1) / median of each):
/// significant_digits of a value 1 with their sum as its spread.
int ratio_digits(double spread_a, double spread_b);

/// `v` with `digits` significant digits, trailing zeros kept (printf "%#.*g" without a
/// trailing point: 0.820, 12, 1.50e-05); "" for a value that is not finite.
std::string number_with_digits(double v, int digits);

/// The machine as a line without commas, from the text of /proc/cpuinfo: "MODEL (N logical
/// CPUs)", MODEL the first "model name" (x86) or else "Hardware"/"cpu model" line, N the count of
/// "processor" lines; "unknown CPU" where none is found. Commas inside are replaced by spaces
/// (the CSVs quote nothing).
std::string machine_description(const std::string& cpuinfo);

/// machine_description of this machine's /proc/cpuinfo ("unknown CPU (0 logical CPUs)" where it
/// cannot be read).
std::string this_machine();

/// The build that made this binary, as a line without commas: the compiler's CMake id and
/// version, the build type and the compile flags of that type (CMAKE_CXX_FLAGS and
/// CMAKE_CXX_FLAGS_<TYPE>, as the engine is compiled), e.g. "GNU 12.2.0 Release -O3 -DNDEBUG",
/// with " sanitizers" at the end in a sanitizer build (CPS_SANITIZE). Set at configure time.
std::string this_build();

/// The load averages over 1, 5 and 15 minutes (runnable processes), from /proc/loadavg: "0.30
/// 0.79 1.16"; "unknown" where it cannot be read.
std::string load_average();

}  // namespace cps::cli
