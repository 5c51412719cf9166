#include "report/timing.h"

#include "cps_build_info.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace cps::cli {
namespace {

// The whole text of a file; "" where it cannot be read.
std::string file_text(const char* path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return in ? text.str() : std::string();
}

// `s` with its leading and trailing blanks removed.
std::string trimmed(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t");
  const std::size_t b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// `s` with every comma replaced by a space and runs of blanks collapsed.
std::string without_commas(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == ',' || c == '\t') c = ' ';
    if (c == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += c;
  }
  return trimmed(out);
}

}  // namespace

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

Quartiles quartiles(std::vector<double> samples) {
  if (samples.empty()) return {std::nan(""), std::nan(""), std::nan("")};
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double p) {
    const double h = p * static_cast<double>(samples.size() - 1);
    const std::size_t lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, samples.size() - 1);
    return samples[lo] + (h - static_cast<double>(lo)) * (samples[hi] - samples[lo]);
  };
  return {at(0.25), at(0.5), at(0.75)};
}

int significant_digits(double q1, double median, double q3) {
  const double spread = q3 - q1;
  if (!(median > 0.0) || !std::isfinite(median) || !(spread > 0.0) || !std::isfinite(spread)) {
    return 3;
  }
  const int digits = static_cast<int>(std::floor(std::log10(median / spread))) + 2;
  return std::clamp(digits, 2, 4);
}

int ratio_digits(double spread_a, double spread_b) {
  return significant_digits(0.0, 1.0, spread_a + spread_b);
}

std::string number_with_digits(double v, int digits) {
  if (!std::isfinite(v)) return "";
  char text[48];
  std::snprintf(text, sizeof text, "%#.*g", digits, v);  // # keeps trailing zeros: 0.820
  std::string out = text;
  const std::size_t e = out.find('e');
  const std::size_t end = e == std::string::npos ? out.size() : e;
  if (end > 0 && out[end - 1] == '.') out.erase(end - 1, 1);  // "12." -> "12"
  return out;
}

std::string machine_description(const std::string& cpuinfo) {
  std::istringstream lines(cpuinfo);
  std::string model, fallback;
  int processors = 0;
  for (std::string line; std::getline(lines, line);) {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trimmed(line.substr(0, colon));
    const std::string value = trimmed(line.substr(colon + 1));
    if (key == "processor") ++processors;
    if (key == "model name" && model.empty()) model = value;
    if ((key == "Hardware" || key == "cpu model") && fallback.empty()) fallback = value;
  }
  if (model.empty()) model = fallback;
  if (model.empty()) model = "unknown CPU";
  return without_commas(model) + " (" + std::to_string(processors) + " logical CPU" +
         (processors == 1 ? ")" : "s)");
}

std::string this_machine() { return machine_description(file_text("/proc/cpuinfo")); }

std::string this_build() {
  std::string b = std::string(CPS_CXX_COMPILER) + " " + CPS_BUILD_TYPE + " " + CPS_CXX_FLAGS;
  if (CPS_SANITIZE_BUILD) b += " sanitizers";
  return without_commas(b);
}

std::string load_average() {
  std::istringstream in(file_text("/proc/loadavg"));
  std::string a, b, c;
  if (!(in >> a >> b >> c)) return "unknown";
  return a + " " + b + " " + c;
}

}  // namespace cps::cli
