#include "report/studies.h"

#include "options/options.h"
#include "report/plan.h"
#include "report/references.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace cps::cli {
namespace {

constexpr const char* kPartNames[] = {"solver_error", "references", "energy"};

// A number cell: number(), "inf" or "-inf" for an infinite value, "" for NaN.
std::string cell(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return number(v);
}

const scenes::Scene* paper_scene(const std::string& name) {
  return has_reference_sections(name) ? scenes::find_scene(name) : nullptr;
}

// Whether a paper scene has the references study: it is not judged by its own reference solution.
bool has_references(const scenes::Scene& scene) { return !scene.report.has_reference_solution; }

// The cells of one row of a study table, read with the file and line for messages.
struct Row {
  const CsvTable& table;
  std::size_t index;
  const std::string& source;

  const std::string& operator[](std::string_view column) const { return table.cell(index, column); }
  std::size_t line() const { return index < table.lines.size() ? table.lines[index] : index + 2; }
  UsageError bad(std::string_view column, const std::string& why) const {
    return UsageError("--merge: " + source + " line " + std::to_string(line()) + ", column " +
                      std::string(column) + ": '" + (*this)[column] + "' " + why);
  }
  // A number: finite, or "inf"/"-inf" where `infinite_ok`; NaN for an empty cell.
  double real(std::string_view column, bool infinite_ok = false) const {
    const std::string& text = (*this)[column];
    if (text.empty()) return std::nan("");
    if (infinite_ok && (text == "inf" || text == "-inf")) {
      return text == "inf" ? HUGE_VAL : -HUGE_VAL;
    }
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) {
      throw bad(column, infinite_ok ? "is not a number (or inf)" : "is not a finite number");
    }
    return v;
  }
  // A count in [0, max].
  long long count(std::string_view column, long long max = 1LL << 40) const {
    const std::string& text = (*this)[column];
    long long v = -1;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < 0 || v > max) {
      throw bad(column, "is not a count in [0, " + std::to_string(max) + "]");
    }
    return v;
  }
  bool flag(std::string_view column) const {
    const std::string& text = (*this)[column];
    if (text != "0" && text != "1") throw bad(column, "is not 0 or 1");
    return text == "1";
  }
};

// The first columns of every scene study's table.
std::vector<std::string> head(std::initializer_list<const char*> own) {
  std::vector<std::string> c = {"study", "quick"};
  c.insert(c.end(), own.begin(), own.end());
  return c;
}

std::string scene_study_id(const std::string& scene, StudyKind kind) {
  return scene + "." + kPartNames[static_cast<int>(kind)];
}

void read_solver_error(const Row& r, SceneStudies& s, bool first) {
  if (first) {
    s.samples = static_cast<int>(r.count("samples", 1000000));
    s.no_solve = static_cast<int>(r.count("no_solve", 1000000));
    if (s.samples == 0) throw r.bad("samples", "is not a count of at least 1");
  }
  if (r["method"].empty()) return;  // a study without a point
  SolverErrorPoint p;
  p.step = r.count("step");
  p.t_s = r.real("t_s");
  p.solve = static_cast<int>(r.count("solve", 1000000));
  p.rows = static_cast<int>(r.count("rows", 1LL << 30));
  p.method = r["method"];
  if (p.method != "exact" && p.method != "pgs" && p.method != "jacobi") {
    throw r.bad("method", "is not exact, pgs or jacobi");
  }
  p.sweeps = static_cast<int>(r.count("sweeps", 1000000));
  p.relative = r.real("lambda_error_relative", true);
  p.velocity_mps = r.real("velocity_error_mps", true);
  p.residual_N = r.real("natural_map_N", true);
  p.refused = r["refused"];
  s.solver_error.push_back(std::move(p));
}

void read_references(const Row& r, SceneStudies& s, bool first) {
  if (first) {
    ReferenceAgreement a;
    a.tolerance_m = r.real("tolerance_m");
    a.horizon_s = r.real("horizon_s", true);
    a.checked_until_s = r.real("checked_until_s");
    a.exact_solves = static_cast<long>(r.count("exact_solves"));
    a.exact_cpu_s = r.real("exact_cpu_s");
    a.stopped = r["stopped"];
    if (!(a.tolerance_m > 0.0)) throw r.bad("tolerance_m", "is not a distance above 0");
    s.agreement = std::move(a);
  }
  if (r["t_s"].empty()) return;
  s.agreement->t_s.push_back(r.real("t_s"));
  s.agreement->distance_m.push_back(r.real("distance_m"));
}

void read_energy(const Row& r, SceneStudies& s) {
  const std::string& push = r["push"];
  if (push.empty()) throw r.bad("push", "is not a push method");
  if (s.energy.empty() || s.energy.back().push != push) {
    EnergyTrace e;
    e.push = push;
    e.diverged_at_s = r.real("diverged_at_s");
    s.energy.push_back(std::move(e));
  }
  EnergyTrace& e = s.energy.back();
  e.t_s.push_back(r.real("t_s"));
  e.kinetic_J.push_back(r.real("kinetic_J", true));
  e.potential_J.push_back(r.real("potential_J", true));
  e.total_J.push_back(r.real("total_J", true));
  e.penetration_m.push_back(r.real("penetration_m", true));
  e.rod_error_m.push_back(r.real("rod_error_m", true));
}

PairRow read_pair(const Row& r, const StudySpec& spec) {
  PairRow p{spec.mass_ratio, spec.solver, spec.push, {}, {}};
  p.outcome.held = r.flag("held");
  p.outcome.heavy_height_m = r.real("heavy_height_m");
  p.outcome.light_offset_m = r.real("light_offset_m");
  p.outcome.overlap_m = r.real("overlap_m");
  p.outcome.finite = !std::isnan(p.outcome.heavy_height_m);
  const std::string& holding = r["iterations_holding"];
  for (std::size_t at = 0; at < holding.size();) {
    const std::size_t end = std::min(holding.find(' ', at), holding.size());
    int n = 0;
    const auto [last, ec] = std::from_chars(holding.data() + at, holding.data() + end, n);
    if (ec != std::errc() || last != holding.data() + end || n < 1) {
      throw r.bad("iterations_holding", "is not a list of iteration counts");
    }
    p.iterations_holding.push_back(n);
    at = end + 1;
  }
  return p;
}

}  // namespace

std::string StudySpec::id() const {
  if (kind == StudyKind::mass_ratio) return pair_id(PairRow{mass_ratio, solver, push, {}, {}});
  return scene_study_id(scene, kind);
}

std::string StudySpec::file_name() const {
  if (kind != StudyKind::mass_ratio) {
    return file_stem(scene) + "_" + kPartNames[static_cast<int>(kind)] + ".csv";
  }
  std::string name = id();
  std::replace(name.begin(), name.end(), '.', '_');
  return name + ".csv";
}

std::optional<StudySpec> StudySpec::parse(const std::string& id) {
  const bool pair = id.rfind("mass_ratio.", 0) == 0;
  for (const PairRow& row : pair ? mass_ratio_rows() : std::vector<PairRow>{}) {
    if (pair_id(row) == id) {
      StudySpec s;
      s.kind = StudyKind::mass_ratio;
      s.mass_ratio = row.mass_ratio;
      s.solver = row.solver;
      s.push = row.push;
      return s;
    }
  }
  if (pair) {
    std::string ratios;
    for (const double r : kMassRatios) ratios += (ratios.empty() ? "" : ", ") + number(r);
    throw UsageError("study id '" + id + "': no row of the mass ratio table; expected "
                     "mass_ratio.R.SOLVER.PUSH with R one of " + ratios + " and a solver the "
                     "push reads ('cps report SCENE --list-runs' lists them)");
  }
  for (int k = 0; k < 3; ++k) {
    const std::string tail = std::string(".") + kPartNames[k];
    if (id.size() <= tail.size() || id.compare(id.size() - tail.size(), tail.size(), tail) != 0) {
      continue;
    }
    StudySpec s;
    s.kind = static_cast<StudyKind>(k);
    s.scene = id.substr(0, id.size() - tail.size());
    const scenes::Scene* scene = paper_scene(s.scene);
    if (scene == nullptr || (s.kind == StudyKind::references && !has_references(*scene))) {
      // Not a study of a paper scene: the id may still be a run's (a scene file's name).
      if (scenes::find_scene(s.scene) != nullptr && scene == nullptr) return std::nullopt;
      throw UsageError("study id '" + id + "': " + s.scene + " has no " + kPartNames[k] +
                       " study (the paper's scenes have them, and references only where the "
                       "scene has no reference solution of its own)");
    }
    return s;
  }
  return std::nullopt;
}

std::vector<StudySpec> plan_studies(const std::vector<const scenes::Scene*>& scenes, bool quick) {
  std::vector<StudySpec> plan;
  for (const scenes::Scene* scene : scenes) {
    const std::string name(scene->name);
    if (!has_reference_sections(name)) continue;
    for (const StudyKind kind : {StudyKind::solver_error, StudyKind::references, StudyKind::energy}) {
      if (kind == StudyKind::references && !has_references(*scene)) continue;
      plan.push_back({.kind = kind, .scene = name, .quick = quick});
    }
  }
  for (const PairRow& row : mass_ratio_rows()) {
    plan.push_back({.kind = StudyKind::mass_ratio, .scene = "", .mass_ratio = row.mass_ratio,
                    .solver = row.solver, .push = row.push, .quick = quick});
  }
  return plan;
}

CsvTable run_study(const StudySpec& spec) {
  if (spec.kind == StudyKind::mass_ratio) {
    PairRow row{spec.mass_ratio, spec.solver, spec.push, {}, {}};
    run_pair_row(row);
    return mass_ratio_table({row});
  }
  SceneStudies s;
  s.quick = spec.quick;
  RunSpec paper{spec.scene};
  paper.quick = spec.quick;
  switch (spec.kind) {
    case StudyKind::solver_error:
      s.samples = spec.quick ? kSolverErrorSamplesQuick : kSolverErrorSamples;
      s.solver_error = sample_solver_error(paper, s.samples, s.no_solve);
      return solver_error_table(spec.scene, s);
    case StudyKind::references:
      if (const ReferenceAgreement* a = scene_agreement(paper.scene_def(), spec.quick)) s.agreement = *a;
      return references_table(spec.scene, s);
    default:
      s.energy = energy_traces(spec.scene, kEnergyPoints, spec.quick);
      return energy_table(spec.scene, s);
  }
}

void add_study_table(const CsvTable& table, const std::string& source, ReportStudies& into) {
  std::string current;  // the id of the rows being read, parsed once into spec
  std::optional<StudySpec> spec;
  for (std::size_t i = 0; i < table.rows.size(); ++i) {
    const Row r{table, i, source};
    const std::string& id = r["study"];
    const bool first = id != current;
    if (first) {
      try {
        spec = StudySpec::parse(id);
      } catch (const UsageError& e) {
        throw r.bad("study", std::string("names no study of this build (") + e.what() + ")");
      }
      if (!spec) throw r.bad("study", "is not a study id");
      if (!into.ids.insert(id).second) {
        throw r.bad("study", "is a study already read from another file or line; each study "
                             "may be merged once: remove one of them");
      }
      current = id;
    }
    if (spec->kind == StudyKind::mass_ratio) {
      if (!first) throw r.bad("study", "is a mass ratio row given twice");
      into.pairs.push_back(read_pair(r, *spec));
      continue;
    }
    SceneStudies& s = into.scenes[spec->scene];
    if (first) s.quick = r.flag("quick");
    switch (spec->kind) {
      case StudyKind::solver_error: read_solver_error(r, s, first); break;
      case StudyKind::references: read_references(r, s, first); break;
      default: read_energy(r, s); break;
    }
  }
  // The table's order, whatever the order the rows were read in.
  const std::vector<PairRow> order = mass_ratio_rows();
  const auto place = [&](const PairRow& p) {
    const std::string id = pair_id(p);
    return std::find_if(order.begin(), order.end(), [&](const PairRow& o) { return pair_id(o) == id; }) -
           order.begin();
  };
  std::stable_sort(into.pairs.begin(), into.pairs.end(),
                   [&](const PairRow& a, const PairRow& b) { return place(a) < place(b); });
}

CsvTable solver_error_table(const std::string& scene, const SceneStudies& studies) {
  CsvTable csv;
  csv.columns = head({"samples", "no_solve", "step", "t_s", "solve", "rows", "method", "sweeps",
                      "lambda_error_relative", "velocity_error_mps", "natural_map_N", "refused"});
  const std::vector<std::string> start = {scene_study_id(scene, StudyKind::solver_error),
                                          studies.quick ? "1" : "0",
                                          std::to_string(studies.samples),
                                          std::to_string(studies.no_solve)};
  for (const SolverErrorPoint& p : studies.solver_error) {
    std::vector<std::string> row = start;
    row.insert(row.end(), {std::to_string(p.step), number(p.t_s), std::to_string(p.solve),
                           std::to_string(p.rows), p.method, std::to_string(p.sweeps),
                           cell(p.relative), cell(p.velocity_mps), cell(p.residual_N), p.refused});
    csv.rows.push_back(std::move(row));
  }
  if (csv.rows.empty()) {
    csv.rows.push_back(start);
    csv.rows.back().resize(csv.columns.size());
  }
  return csv;
}

CsvTable references_table(const std::string& scene, const SceneStudies& studies) {
  CsvTable csv;
  csv.columns = head({"tolerance_m", "horizon_s", "checked_until_s", "exact_solves", "exact_cpu_s",
                      "stopped", "t_s", "distance_m"});
  if (!studies.agreement) return csv;
  const ReferenceAgreement& a = *studies.agreement;
  const std::vector<std::string> start = {
      scene_study_id(scene, StudyKind::references), studies.quick ? "1" : "0",
      number(a.tolerance_m), cell(a.horizon_s), number(a.checked_until_s),
      std::to_string(a.exact_solves), number(a.exact_cpu_s), a.stopped};
  for (std::size_t i = 0; i < a.t_s.size(); ++i) {
    std::vector<std::string> row = start;
    row.insert(row.end(), {number(a.t_s[i]), number(a.distance_m[i])});
    csv.rows.push_back(std::move(row));
  }
  if (csv.rows.empty()) {
    csv.rows.push_back(start);
    csv.rows.back().resize(csv.columns.size());
  }
  return csv;
}

CsvTable energy_table(const std::string& scene, const SceneStudies& studies) {
  CsvTable csv;
  csv.columns = head({"push", "diverged_at_s", "t_s", "kinetic_J", "potential_J", "total_J",
                      "penetration_m", "rod_error_m"});
  const std::string id = scene_study_id(scene, StudyKind::energy);
  for (const EnergyTrace& e : studies.energy) {
    for (std::size_t i = 0; i < e.t_s.size(); ++i) {
      csv.rows.push_back({id, studies.quick ? "1" : "0", e.push, number(e.diverged_at_s),
                          number(e.t_s[i]), cell(e.kinetic_J[i]), cell(e.potential_J[i]),
                          cell(e.total_J[i]), cell(e.penetration_m[i]), cell(e.rod_error_m[i])});
    }
  }
  return csv;
}

}  // namespace cps::cli
