#include "report/result.h"

#include "options/options.h"
#include "output/output.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <stdexcept>
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
    {"cpu_s_per_sim_s", &RunResult::cpu_s_per_sim_s},
    {"cpu_s_per_sim_s_q1", &RunResult::cpu_s_per_sim_s_q1},
    {"cpu_s_per_sim_s_q3", &RunResult::cpu_s_per_sim_s_q3},
    {"cpu_s_per_sim_s_min", &RunResult::cpu_s_per_sim_s_min},
    {"us_per_step", &RunResult::us_per_step},
    {"trajectory_time_s", &RunResult::trajectory_time_s},
    {"trajectory_error_m", &RunResult::trajectory_error_m},
    {"reference_check_m", &RunResult::reference_check_m},
    {"reference_order", &RunResult::reference_order},
    {"reference_error_m", &RunResult::reference_error_m},
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
    "horizon_s", "diverged", "diverged_at_s", "diverged_why", "cpu_s_per_sim_s", "cpu_s_per_sim_s_q1",
    "cpu_s_per_sim_s_q3", "cpu_s_per_sim_s_min", "us_per_step", "timing_repeats", "runs_per_repeat",
    "timing_threads", "reference_substeps",
    "trajectory_time_s", "trajectory_error_m", "reference_check_m", "reference_order",
    "reference_error_m", "under_reference_error",
    "phase_error_deg",
    "residual_max_N", "residual_rms_N", "penetration_max_m", "penetration_rms_m",
    "rod_error_max_m", "rod_error_rms_m", "energy_drift_rel", "sweep", "quick", "machine",
    "build"};

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

// What a cell's text is as a number: all of it a finite number (strtod), all of it a number
// that is not finite ("nan", "inf", "1e999"), or not a number.
enum class NumberText { finite, non_finite, not_number };

NumberText number_text(const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return NumberText::not_number;
  return std::isfinite(v) ? NumberText::finite : NumberText::non_finite;
}

// Why the non-empty cell `text` cannot be in column `column` of a report CSV, or "": a number
// column (a measure, a metric, warm_start) holds a finite number, diverged and quick hold 0 or
// 1, and no cell holds a number that is not finite (the CSVs write none: number()).
std::string bad_cell(const std::string& column, const std::string& text) {
  const NumberText kind = number_text(text);
  if (kind == NumberText::non_finite) {
    return "is not finite (a report CSV holds finite numbers; a measure without a value is an "
           "empty cell)";
  }
  const bool numeric = number_field(column) != nullptr || column == "warm_start" ||
                       column.rfind(kMetricPrefix, 0) == 0;
  if (numeric && kind == NumberText::not_number) return "is not a number";
  if ((column == "diverged" || column == "quick" || column == "under_reference_error") &&
      text != "0" && text != "1") {
    return "is not 0 or 1";
  }
  return "";
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
  } else if (column == "iterations" || column == "substeps" || column == "timing_repeats" ||
             column == "runs_per_repeat" || column == "timing_threads" ||
             column == "reference_substeps") {
    const std::optional<int> n = parse_count(text);
    if (!n) return false;
    if (column == "iterations") r.iterations = *n;
    if (column == "substeps") r.substeps = *n;
    if (column == "timing_repeats") r.timing_repeats = *n;
    if (column == "runs_per_repeat") r.runs_per_repeat = *n;
    if (column == "timing_threads") r.timing_threads = *n;
    if (column == "reference_substeps") r.reference_substeps = *n;
  } else if (column == "warm_start") {
    const double w = parse_number(text);
    r.warm_start = std::isnan(w) ? 0.0 : w;
  } else if (column == "diverged") {
    r.diverged = text == "1";
  } else if (column == "diverged_why") {
    r.diverged_why = text;
  } else if (column == "under_reference_error") {
    r.under_reference_error = text == "1";
  } else if (column == "sweep") {
    r.sweep = text;
  } else if (column == "quick") {
    r.quick = text == "1";
  } else if (column == "machine") {
    r.machine = text;
  } else if (column == "build") {
    r.build = text;
  } else {
    r.other[column] = text;
  }
  return true;
}

// Row `row` of `table` as a result. Throws UsageError naming `source`, the line, the column and
// the cell for a cell it cannot hold (bad_cell) or a count that is not one, and for a missing
// setting.
RunResult result_of_row(const CsvTable& table, std::size_t row, const std::string& source) {
  RunResult r;
  const std::size_t line = row < table.lines.size() ? table.lines[row] : row + 2;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    const std::string& text = table.rows[row][c];
    if (text.empty()) continue;
    std::string why = bad_cell(table.columns[c], text);
    if (why.empty() && !set_cell(r, table.columns[c], text)) why = "is not a count";
    if (!why.empty()) {
      throw UsageError("--merge: " + source + " line " + std::to_string(line) + ", column " +
                       table.columns[c] + ": '" + text + "' " + why);
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

PushReads RunResult::reads() const {
  const Choice* c = parameter("push").find_choice(push);
  return c != nullptr ? push_reads(static_cast<PushMode>(c->value)) : PushReads{};
}

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
  if (column == "runs_per_repeat") {
    return runs_per_repeat ? std::optional<std::string>(std::to_string(*runs_per_repeat)) : std::nullopt;
  }
  if (column == "timing_threads") {
    return timing_threads ? std::optional<std::string>(std::to_string(*timing_threads)) : std::nullopt;
  }
  if (column == "reference_substeps") {
    return reference_substeps ? std::optional<std::string>(std::to_string(*reference_substeps))
                              : std::nullopt;
  }
  if (column == "diverged_why") return diverged_why;
  if (column == "under_reference_error") {
    return under_reference_error ? std::optional<std::string>(*under_reference_error ? "1" : "0")
                                 : std::nullopt;
  }
  if (column == "machine") return machine;
  if (column == "build") return build;
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

namespace {

// The size of the CSVs a merge reads, counted before any is parsed.
struct MergeSize {
  std::uintmax_t bytes = 0;  // of the files
  std::uintmax_t rows = 0;   // non-empty lines after each header
  std::uintmax_t cells = 0;  // rows x their file's header columns (read_csv makes every cell)
  std::uintmax_t estimate() const { return bytes + cells * kMergeBytesPerCell; }
};

std::string mib(std::uintmax_t bytes) {
  return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

// Adds `file` to `size` (reading it in blocks, nothing kept). Throws UsageError once the
// estimate passes kMergeMemoryLimit, so a huge file is not read to its end.
void add_size(MergeSize& size, const fs::path& file, std::size_t file_count) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::vector<char> block(1 << 16);
  bool header = true;
  bool in_row = false;
  std::uintmax_t columns = 1;
  const auto end_row = [&] {
    if (in_row) {
      ++size.rows;
      size.cells += columns;
    }
    in_row = false;
  };
  for (;;) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const std::size_t n = static_cast<std::size_t>(in.gcount());
    if (n == 0) break;
    size.bytes += n;
    for (std::size_t i = 0; i < n; ++i) {
      const char c = block[i];
      if (header) {
        if (c == '\n') header = false;
        else if (c == ',') ++columns;
      } else if (c == '\n') {
        end_row();
      } else {
        in_row = true;
      }
    }
    if (size.estimate() + (header ? columns * kMergeBytesPerCell : 0) > kMergeMemoryLimit) {
      throw UsageError("--merge: the CSV files below the given folders hold at least " +
                       std::to_string(size.rows) + " rows, " + std::to_string(size.cells) +
                       " cells and " + std::to_string(size.bytes) + " bytes (read up to " +
                       file.string() + ", file " + std::to_string(file_count) +
                       "): merging them would take at least " + mib(size.estimate()) +
                       " of memory (" + std::to_string(kMergeBytesPerCell) +
                       " bytes per cell, plus the text); the limit is " + mib(kMergeMemoryLimit) +
                       ". Merge fewer runs at once, e.g. one sweep's folder");
    }
  }
  end_row();
}

}  // namespace

namespace {

// The first 5 bytes of a file's header ("scene" for a run table, "study" for a study table):
// a file of any size (a single line of gigabytes) is never read further here; the merge's size
// bound reads the rest in blocks.
std::string header_start(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char start[5] = {};
  in.read(start, sizeof start);
  return std::string(start, static_cast<std::size_t>(in.gcount()));
}

// True for a table that holds neither runs nor studies and is left alone: an older build's
// mass_ratio.csv or reference section (SCENE_solver_error.csv, SCENE_references.csv,
// SCENE_energy.csv) whose header starts with neither 'scene' nor 'study'.
bool is_older_table(const fs::path& file) {
  const std::string name = file.filename().string();
  const auto ends_with = [&](const std::string& tail) {
    return name.size() > tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (name != "mass_ratio.csv" && !ends_with("_solver_error.csv") && !ends_with("_references.csv") &&
      !ends_with("_energy.csv")) {
    return false;
  }
  const std::string start = header_start(file);
  return start != "scene" && start != "study";
}

}  // namespace

ReportCsvs read_results(const std::vector<fs::path>& dirs) {
  // Every CSV once, with the folder it was found below.
  std::vector<std::pair<fs::path, fs::path>> sources;  // file, given folder
  std::map<fs::path, fs::path> seen;                    // canonical file -> given folder
  for (const fs::path& dir : dirs) {
    if (!fs::is_directory(dir)) {
      throw UsageError("--merge " + dir.string() + ": no such folder (give folders holding the "
                       "CSV files of report runs)");
    }
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file() && entry.path().extension() == ".csv" &&
          !is_older_table(entry.path())) {
        files.push_back(entry.path());
      }
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      const auto [it, fresh] = seen.emplace(fs::weakly_canonical(file), dir);
      if (!fresh) {
        throw UsageError("--merge: " + file.string() + " is below both " + it->second.string() +
                         " and " + dir.string() + " (a folder given twice, or one inside "
                         "another): its runs would be merged twice; give each folder once");
      }
      sources.emplace_back(file, dir);
      note_input(file);  // never an output of this merge
    }
  }
  MergeSize size;
  for (std::size_t k = 0; k < sources.size(); ++k) add_size(size, sources[k].first, k + 1);

  ReportCsvs csvs;
  std::vector<RunResult>& results = csvs.runs;
  std::map<std::string, std::pair<std::string, std::size_t>> first;  // run id -> file, line
  for (const auto& [file, dir] : sources) {
    CsvTable table = read_csv(file);
    if (!table.columns.empty() && table.columns.front() == "study") {
      csvs.studies.emplace_back(file.string(), std::move(table));
      continue;
    }
    std::vector<RunResult> rows = results_of(table, file.string());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::size_t line = k < table.lines.size() ? table.lines[k] : k + 2;
      const std::string id = rows[k].id();
      const auto [it, fresh] = first.emplace(id, std::make_pair(file.string(), line));
      if (!fresh) {
        throw UsageError("--merge: run " + id + " is in " + it->second.first + " line " +
                         std::to_string(it->second.second) + " and again in " + file.string() +
                         " line " + std::to_string(line) +
                         "; each run may be merged once: remove one of them");
      }
      results.push_back(std::move(rows[k]));
    }
  }
  return csvs;
}

}  // namespace cps::cli
