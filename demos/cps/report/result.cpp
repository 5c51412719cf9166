#include "report/result.h"

#include "options/options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <utility>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// The columns of the measures held as numbers, by name.
using NumberField = std::optional<double> RunResult::*;
constexpr std::pair<std::string_view, NumberField> kNumberColumns[] = {
    {"dt_s", &RunResult::dt_s},
    {"horizon_s", &RunResult::horizon_s},
    {"diverged_at_s", &RunResult::diverged_at_s},
    {"wall_s_per_sim_s", &RunResult::wall_s_per_sim_s},
    {"us_per_step", &RunResult::us_per_step},
    {"trajectory_time_s", &RunResult::trajectory_time_s},
    {"trajectory_error_m", &RunResult::trajectory_error_m},
    {"reference_check_m", &RunResult::reference_check_m},
    {"phase_error_deg", &RunResult::phase_error_deg},
    {"residual_max_N", &RunResult::residual_max_N},
    {"residual_rms_N", &RunResult::residual_rms_N},
    {"penetration_max_m", &RunResult::penetration_max_m},
    {"penetration_rms_m", &RunResult::penetration_rms_m},
    {"rod_error_max_m", &RunResult::rod_error_max_m},
    {"rod_error_rms_m", &RunResult::rod_error_rms_m},
    {"energy_drift_rel", &RunResult::energy_drift_rel},
};

// Every column this build knows, in the order of the CSVs: the settings, then the measures, then
// the sweep. Metrics and other columns follow, sorted by name.
constexpr std::string_view kColumnOrder[] = {
    "scene", "solver", "push", "friction_model", "iterations", "substeps", "warm_start", "dt_s",
    "horizon_s", "diverged", "diverged_at_s", "wall_s_per_sim_s", "us_per_step", "timing_repeats",
    "trajectory_time_s", "trajectory_error_m", "reference_check_m", "phase_error_deg",
    "residual_max_N", "residual_rms_N", "penetration_max_m", "penetration_rms_m",
    "rod_error_max_m", "rod_error_rms_m", "energy_drift_rel", "sweep", "quick"};

constexpr std::string_view kMetricPrefix = "metric.";

const NumberField* number_field(std::string_view column) {
  for (const auto& [name, field] : kNumberColumns) {
    if (name == column) return &field;
  }
  return nullptr;
}

// A count as the CSV writes it (decimal digits), or std::nullopt.
std::optional<int> parse_count(const std::string& text) {
  int n = 0;
  const char* last = text.c_str() + text.size();
  const auto [end, ec] = std::from_chars(text.c_str(), last, n);
  if (text.empty() || ec != std::errc() || end != last) return std::nullopt;
  return n;
}

// Sets the column `column` of `r` from its non-empty cell `text`. False for a count that is not
// one.
bool set_cell(RunResult& r, const std::string& column, const std::string& text) {
  if (const NumberField* f = number_field(column)) {
    r.*(*f) = parse_number(text);
  } else if (column.rfind(kMetricPrefix, 0) == 0) {
    r.metrics[column.substr(kMetricPrefix.size())] = parse_number(text);
  } else if (column == "scene") {
    r.scene = text;
  } else if (column == "solver") {
    r.solver = text;
  } else if (column == "push") {
    r.push = text;
  } else if (column == "friction_model") {
    r.friction_model = text;
  } else if (column == "iterations" || column == "substeps" || column == "timing_repeats") {
    const std::optional<int> n = parse_count(text);
    if (!n) return false;
    if (column == "iterations") r.iterations = *n;
    if (column == "substeps") r.substeps = *n;
    if (column == "timing_repeats") r.timing_repeats = *n;
  } else if (column == "warm_start") {
    const double w = parse_number(text);
    r.warm_start = std::isnan(w) ? 0.0 : w;
  } else if (column == "diverged") {
    r.diverged = text == "1";
  } else if (column == "sweep") {
    r.sweep = text;
  } else if (column == "quick") {
    r.quick = text == "1";
  } else {
    r.other[column] = text;
  }
  return true;
}

// Row `row` of `table` as a result. Throws UsageError naming `source` for a count that is not
// one or a missing setting.
RunResult result_of_row(const CsvTable& table, std::size_t row, const std::string& source) {
  RunResult r;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    const std::string& text = table.rows[row][c];
    if (text.empty()) continue;
    if (!set_cell(r, table.columns[c], text)) {
      throw UsageError("--merge: " + source + ": '" + text + "' in column " + table.columns[c] +
                       " is not a count");
    }
  }
  for (const char* setting : {"solver", "push", "friction_model", "iterations", "substeps", "diverged"}) {
    if (table.cell(row, setting).empty()) {
      throw UsageError("--merge: " + source + " is not a cps report CSV (a row without " +
                       setting + ")");
    }
  }
  return r;
}

}  // namespace

std::string RunResult::id() const {
  return run_id(scene, solver, push, friction_model, iterations, substeps, warm_start);
}

std::string RunResult::variant() const { return solver + " " + push + " " + friction_model; }

bool RunResult::is_paper_setting() const {
  return solver == "pgs" && push == "baumgarte" && friction_model == "fixed" &&
         iterations == kPaperIterations && substeps == 1 && warm_start == 0.0;
}

double RunResult::value(std::string_view column) const {
  if (const NumberField* f = number_field(column)) return (this->*(*f)).value_or(std::nan(""));
  if (column.substr(0, kMetricPrefix.size()) == kMetricPrefix) {
    const auto it = metrics.find(std::string(column.substr(kMetricPrefix.size())));
    return it == metrics.end() ? std::nan("") : it->second;
  }
  return parse_number(cell(column).value_or(""));
}

std::optional<std::string> RunResult::cell(std::string_view column) const {
  if (const NumberField* f = number_field(column)) {
    const std::optional<double>& v = this->*(*f);
    return v ? std::optional<std::string>(number(*v)) : std::nullopt;
  }
  if (column.substr(0, kMetricPrefix.size()) == kMetricPrefix) {
    const auto it = metrics.find(std::string(column.substr(kMetricPrefix.size())));
    return it == metrics.end() ? std::nullopt : std::optional<std::string>(number(it->second));
  }
  if (column == "scene") return scene;
  if (column == "solver") return solver;
  if (column == "push") return push;
  if (column == "friction_model") return friction_model;
  if (column == "iterations") return std::to_string(iterations);
  if (column == "substeps") return std::to_string(substeps);
  if (column == "warm_start") return shortest_decimal(warm_start);
  if (column == "diverged") return std::string(diverged ? "1" : "0");
  if (column == "timing_repeats") {
    return timing_repeats ? std::optional<std::string>(std::to_string(*timing_repeats)) : std::nullopt;
  }
  if (column == "sweep") return sweep;
  if (column == "quick") {
    return quick ? std::optional<std::string>(*quick ? "1" : "0") : std::nullopt;
  }
  const auto it = other.find(std::string(column));
  return it == other.end() ? std::nullopt : std::optional<std::string>(it->second);
}

RunResult result_of(const RunSpec& spec) {
  RunResult r;
  r.scene = spec.scene;
  r.solver = name_of(spec.solver);
  r.push = name_of(spec.push);
  r.friction_model = name_of(spec.friction_model);
  r.iterations = spec.iterations;
  r.substeps = spec.substeps;
  r.warm_start = spec.warm_start;
  return r;
}

CsvTable results_table(const std::vector<RunResult>& results) {
  CsvTable table;
  for (const std::string_view column : kColumnOrder) {
    const bool any = std::any_of(results.begin(), results.end(),
                                 [&](const RunResult& r) { return r.cell(column).has_value(); });
    if (any) table.columns.emplace_back(column);
  }
  std::set<std::string> rest;
  for (const RunResult& r : results) {
    for (const auto& kv : r.metrics) rest.insert(std::string(kMetricPrefix) + kv.first);
    for (const auto& kv : r.other) rest.insert(kv.first);
  }
  table.columns.insert(table.columns.end(), rest.begin(), rest.end());
  for (const RunResult& r : results) {
    std::vector<std::string>& row = table.rows.emplace_back();
    for (const std::string& column : table.columns) row.push_back(r.cell(column).value_or(""));
  }
  return table;
}

std::vector<RunResult> results_of(const CsvTable& table, const std::string& source) {
  if (table.columns.empty() || table.columns[0] != "scene") {
    throw UsageError("--merge: " + source +
                     " is not a cps report CSV (its header does not start with 'scene')");
  }
  std::vector<RunResult> results;
  for (std::size_t i = 0; i < table.rows.size(); ++i) results.push_back(result_of_row(table, i, source));
  return results;
}

void write_results(const fs::path& file, const std::vector<RunResult>& results) {
  write_csv(file, results_table(results));
}

std::vector<RunResult> read_results(const std::vector<fs::path>& dirs) {
  std::vector<RunResult> results;
  for (const fs::path& dir : dirs) {
    if (!fs::is_directory(dir)) {
      throw UsageError("--merge " + dir.string() + ": no such folder (give folders holding the "
                       "CSV files of report runs)");
    }
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      // mass_ratio.csv (the report's mass ratio table) holds no runs.
      if (entry.is_regular_file() && entry.path().extension() == ".csv" &&
          entry.path().filename() != "mass_ratio.csv") {
        files.push_back(entry.path());
      }
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      for (RunResult& r : results_of(read_csv(file), file.string())) results.push_back(std::move(r));
    }
  }
  return results;
}

}  // namespace cps::cli
