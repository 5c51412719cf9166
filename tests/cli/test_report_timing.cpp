// The report's timing method in-process (demos/cps/report/timing.h): quartiles of the repeats,
// the significant digits a spread supports, the machine read from /proc/cpuinfo's text, and
// the build; the threads that compute a report's runs. No test here times anything against a
// limit.
#include "report/timing.h"

#include "report/tasks.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

using namespace cps::cli;

TEST_CASE("quartiles of timed repeats interpolate between order statistics", "[report][timing]") {
  // Five repeats in any order: Q1, the median and Q3 are the 2nd, 3rd and 4th smallest.
  const Quartiles five = quartiles({0.5, 0.1, 0.4, 0.2, 0.3});
  CHECK(five.q1 == Approx(0.2));
  CHECK(five.median == Approx(0.3));
  CHECK(five.q3 == Approx(0.4));
  // Four: the quantile p sits at h = p (n - 1) in the sorted list: Q1 at 0.75, three quarters
  // of the way from x0 to x1; the median halfway between the middle two.
  const Quartiles four = quartiles({1.0, 2.0, 3.0, 4.0});
  CHECK(four.q1 == Approx(1.75));
  CHECK(four.median == Approx(2.5));
  CHECK(four.q3 == Approx(3.25));
  // Three (the fewest --repeats): Q1 and Q3 halfway to the neighbours of the median.
  const Quartiles three = quartiles({3.0, 1.0, 2.0});
  CHECK(three.q1 == Approx(1.5));
  CHECK(three.median == Approx(2.0));
  CHECK(three.q3 == Approx(2.5));
  // One value: no spread. None: NaN.
  const Quartiles one = quartiles({7.0});
  CHECK((one.q1 == 7.0 && one.median == 7.0 && one.q3 == 7.0));
  CHECK(std::isnan(quartiles({}).median));
  // Always Q1 <= median <= Q3, an outlier moving only Q3 a little, never the median.
  const Quartiles outlier = quartiles({1.0, 1.01, 1.02, 1.03, 50.0});
  CHECK(outlier.median == Approx(1.02));
  CHECK(outlier.q3 == Approx(1.03));
}

TEST_CASE("times are printed with the significant digits their interquartile range supports",
          "[report][timing]") {
  // A spread of 2.4 % of the median: the third digit is the first uncertain one.
  CHECK(significant_digits(0.1220, 0.1234, 0.1250) == 3);
  // 20 %: two digits; 0.1 % and less: four, the most.
  CHECK(significant_digits(0.9, 1.0, 1.1) == 2);
  CHECK(significant_digits(0.9995, 1.0, 1.0005) == 4);
  CHECK(significant_digits(1.0 - 1e-9, 1.0, 1.0 + 1e-9) == 4);
  // A spread larger than the median: still two.
  CHECK(significant_digits(0.1, 1.0, 5.0) == 2);
  // No spread, or nothing to measure: three.
  CHECK(significant_digits(1.0, 1.0, 1.0) == 3);
  CHECK(significant_digits(std::nan(""), std::nan(""), std::nan("")) == 3);
  // A ratio of two times: their relative spreads add (1 % + 1.5 % = 2.5 %: three digits).
  CHECK(ratio_digits(0.01, 0.015) == 3);
  CHECK(ratio_digits(0.1, 0.15) == 2);
  // Trailing zeros stay, a bare point goes, exponents are kept.
  CHECK(number_with_digits(0.82, 3) == "0.820");
  CHECK(number_with_digits(12.0, 2) == "12");
  CHECK(number_with_digits(0.000186685, 3) == "0.000187");
  CHECK(number_with_digits(1.5e-5, 3) == "1.50e-05");
  CHECK(number_with_digits(std::nan(""), 3).empty());
}

TEST_CASE("the machine is read from /proc/cpuinfo's text and holds no comma", "[report][timing]") {
  const std::string x86 =
      "processor\t: 0\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) CPU, 2.20GHz\n"
      "cpu cores\t: 1\n\nprocessor\t: 1\nvendor_id\t: GenuineIntel\n"
      "model name\t: Intel(R) Xeon(R) CPU, 2.20GHz\ncpu cores\t: 1\n";
  CHECK(machine_description(x86) == "Intel(R) Xeon(R) CPU 2.20GHz (2 logical CPUs)");
  // An ARM kernel without "model name": the Hardware line.
  CHECK(machine_description("processor\t: 0\nBogoMIPS\t: 48.00\nHardware\t: BCM2835\n") ==
        "BCM2835 (1 logical CPU)");
  CHECK(machine_description("") == "unknown CPU (0 logical CPUs)");
  // This machine's, and this build's: no comma (the CSVs quote nothing), not empty.
  for (const std::string& line : {this_machine(), this_build(), load_average()}) {
    INFO(line);
    CHECK(!line.empty());
    CHECK(line.find(',') == std::string::npos);
  }
  CHECK(this_machine().find("logical CPU") != std::string::npos);
}

TEST_CASE("the thread's CPU clock advances with work done and never runs backwards",
          "[report][timing]") {
  const double start = thread_cpu_seconds();
  volatile double sink = 0.0;
  double last = start;
  for (int k = 0; k < 2000000; ++k) {
    sink = sink + std::sqrt(static_cast<double>(k));
    if (k % 100000 == 0) {
      const double now = thread_cpu_seconds();
      CHECK(now >= last);
      last = now;
    }
  }
  CHECK(thread_cpu_seconds() > start);
}

TEST_CASE("run_tasks runs each task once on any number of threads and rethrows the first failure",
          "[report][timing]") {
  for (const int jobs : {1, 2, 7}) {
    std::vector<std::atomic<int>> ran(50);
    std::vector<std::function<void()>> tasks;
    for (std::size_t i = 0; i < ran.size(); ++i) tasks.push_back([&ran, i] { ++ran[i]; });
    std::vector<std::size_t> done;
    run_tasks(tasks, jobs, [&](std::size_t i) { done.push_back(i); });
    for (const std::atomic<int>& n : ran) CHECK(n == 1);
    std::sort(done.begin(), done.end());
    CHECK(done.size() == ran.size());
    CHECK(std::adjacent_find(done.begin(), done.end()) == done.end());
  }
  // A failing task: its exception reaches the caller (the lowest-numbered one if several fail),
  // and with one thread no task after it is begun.
  std::vector<int> order;
  const std::vector<std::function<void()>> failing = {
      [&] { order.push_back(0); }, [&] { throw std::runtime_error("task 1"); },
      [&] { order.push_back(2); }};
  CHECK_THROWS_WITH(run_tasks(failing, 1, {}), "task 1");
  CHECK(order == std::vector<int>{0});
  CHECK_THROWS_WITH(run_tasks(failing, 3, {}), "task 1");
  // No tasks: nothing runs, nothing is reported.
  run_tasks({}, 4, [](std::size_t) { FAIL("no task ran"); });
}

TEST_CASE("OnceCache makes a key's value once however many threads ask at once", "[report][timing]") {
  OnceCache<int> cache;
  std::atomic<int> made{0};
  std::vector<int> got(40, 0);  // each task writes its own entry; checked after the threads end
  std::vector<std::function<void()>> tasks;
  for (int i = 0; i < 40; ++i) {
    tasks.push_back([&, i] {
      got[static_cast<std::size_t>(i)] =
          cache.get(i % 2 ? "odd" : "even", [&] { ++made; return i % 2 ? 1 : 2; });
    });
  }
  run_tasks(tasks, 4, {});
  CHECK(made == 2);
  for (int i = 0; i < 40; ++i) CHECK(got[static_cast<std::size_t>(i)] == (i % 2 ? 1 : 2));
}
