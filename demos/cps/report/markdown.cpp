#include "report/markdown.h"

#include "report/headline.h"
#include "report/mass_ratio.h"
#include "report/references.h"
#include "report/run.h"
#include "report/timing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace cps::cli {
namespace {

using Runs = std::vector<const RunResult*>;

// The text of a run's column as its CSV has it; "" where the run has none.
std::string text(const RunResult& r, std::string_view column) { return r.cell(column).value_or(""); }

// A run's time (CPU s per simulated s, the median of its repeats); NaN where it has none.
double time_of(const RunResult& r) { return r.value("cpu_s_per_sim_s"); }

// The relative spread of a run's time: its interquartile range over its median; 0 where a
// quartile is missing.
double spread_of(const RunResult& r) {
  const double q1 = r.value("cpu_s_per_sim_s_q1"), q3 = r.value("cpu_s_per_sim_s_q3");
  const double t = time_of(r);
  return std::isfinite(q1) && std::isfinite(q3) && t > 0.0 ? (q3 - q1) / t : 0.0;
}

// A run's time as report.md prints it: the median with the significant digits its quartiles
// support (significant_digits).
std::string time_text(const RunResult& r) {
  const double t = time_of(r);
  const double q1 = r.value("cpu_s_per_sim_s_q1"), q3 = r.value("cpu_s_per_sim_s_q3");
  return number_with_digits(
      t, std::isfinite(q1) && std::isfinite(q3) ? significant_digits(q1, t, q3) : 3);
}

// The ratio of run a's time to run b's with the digits their spreads support (ratio_digits),
// and in brackets the range their quartiles allow (a's Q1 over b's Q3 to a's Q3 over b's Q1)
// where both have them and they are two runs.
std::string ratio_text(const RunResult& a, const RunResult& b) {
  const int digits = ratio_digits(spread_of(a), spread_of(b));
  std::string out = number_with_digits(time_of(a) / time_of(b), digits);
  const double a1 = a.value("cpu_s_per_sim_s_q1"), a3 = a.value("cpu_s_per_sim_s_q3");
  const double b1 = b.value("cpu_s_per_sim_s_q1"), b3 = b.value("cpu_s_per_sim_s_q3");
  if (&a != &b && std::isfinite(a1) && std::isfinite(a3) && b1 > 0.0 && b3 > 0.0) {
    out += " (" + number_with_digits(a1 / b3, digits) + " to " +
           number_with_digits(a3 / b1, digits) + ")";
  }
  return out;
}

// The INCOMPLETE notice: how many planned runs are missing, the first 20 of them by id.
void write_missing(std::ostream& md, const ReportContent& c) {
  md << "**INCOMPLETE: " << c.missing.size() << " of the " << c.planned
     << " planned runs are missing.** Every table and diagram below lacks them; the "
        "headline compares only the runs present. Missing:";
  for (std::size_t i = 0; i < c.missing.size() && i < 20; ++i) {
    md << (i ? ", " : " ") << "`" << c.missing[i] << "`";
  }
  if (c.missing.size() > 20) md << " and " << c.missing.size() - 20 << " more";
  md << ".\n\n";
}

// The range of a count column over the runs: "5", "3 to 5", or `none` where no run has it.
std::string count_range(const ReportContent& c, std::optional<int> RunResult::*field,
                        const std::string& none) {
  int least = 1 << 30, most = 0;
  for (const auto& [scene, runs] : c.runs) {
    for (const RunResult* r : runs) {
      const int n = (r->*field).value_or(0);
      if (n > 0) least = std::min(least, n), most = std::max(most, n);
    }
  }
  if (most > 0 && least == most) return std::to_string(most);
  if (most > 0) return std::to_string(least) + " to " + std::to_string(most);
  return none;
}

// The distinct values of a text column of the runs (machine, build), sorted; "" left out.
std::set<std::string> distinct(const ReportContent& c, std::string_view column) {
  std::set<std::string> values;
  for (const auto& [scene, runs] : c.runs) {
    for (const RunResult* r : runs) {
      const std::string v = text(*r, column);
      if (!v.empty()) values.insert(v);
    }
  }
  return values;
}

// Where the times were measured: the machines and builds the runs name, and the load.
void write_timed_on(std::ostream& md, const ReportContent& c) {
  const auto list = [&md](const std::set<std::string>& values) {
    if (values.empty()) md << "not recorded (runs of an older build)";
    bool first = true;
    for (const std::string& v : values) {
      md << (first ? "" : "; ") << "`" << v << "`";
      first = false;
    }
  };
  const std::set<std::string> machines = distinct(c, "machine"), builds = distinct(c, "build");
  md << "- **Timed on** ";
  list(machines);
  md << "; **built with** ";
  list(builds);
  md << ".";
  if (machines.size() > 1 || builds.size() > 1) {
    md << " **The runs were timed on more than one machine or build: times and time ratios "
          "across them compare the machines as much as the methods.**";
  }
  if (!c.load.empty()) md << " " << c.load;
  md << "\n";
}

// What the numbers are: time and where it was measured, divergence, trajectory error, residual,
// substeps, warm start, round-off floors.
void write_definitions(std::ostream& md, const ReportContent& c) {
  md << "Made by `cps report` from " << c.run_count << " runs. What the numbers are:\n\n"
     << "- **Time (s/s)**: physics CPU time per simulated second (column cpu_s_per_sim_s): the "
        "CPU time of the thread that steps (CLOCK_THREAD_CPUTIME_ID, so other processes on the "
        "machine do not add to it), of the step alone (no metrics, no residual), the median of "
     << count_range(c, &RunResult::timing_repeats, "the")
     << " timed repeats (column timing_repeats), each on a fresh world, after one untimed "
        "warm-up repeat, stepped on "
     << count_range(c, &RunResult::timing_threads, "an unrecorded number of")
     << " threads at once (column timing_threads; `cps report --jobs`): each repeat is charged "
        "its own thread's CPU time, but threads at once share the machine's caches and memory "
        "(docs/benchmarks.md measures what that changes); a run shorter than " << number(kMinRepeatSeconds)
     << " s of CPU is stepped several times over in each repeat (runs_per_repeat) and its "
        "time is per run. The repeats of a sweep's runs are interleaved, a round of every run "
        "after another, so that a change of the machine's load or clock falls on all of them "
        "alike. The first and third quartiles of the repeats are cpu_s_per_sim_s_q1 and _q3 "
        "(the error bars of the diagrams), the least repeat cpu_s_per_sim_s_min (the one the "
        "machine disturbed least). Times are printed with the digits their spread "
        "supports (one past the first that the interquartile range leaves uncertain, 2 to 4); "
        "a time ratio with the digits of its two times' spreads together and, in brackets, the "
        "range their quartiles allow. **Quartiles and brackets cover the repeats of this one "
        "report**: a report made at another time, or under another load, can put a run's time "
        "outside them (docs/benchmarks.md, \"Can the report's times be trusted?\"), so check a "
        "ratio against a second report before quoting it. A diverged run is timed until it "
        "diverged.\n";
  write_timed_on(md, c);
  md << "- **Diverged**: the state stopped being finite, or a penetration or rod error passed "
        "the size of the largest movable body (the time: diverged_at_s). Its other measures "
        "stop there and are left out of the headline. In the diagrams it is a red x on the top "
        "edge, at its time until it diverged.\n"
     << "- **Trajectory error (m)**: RMS distance of the movable bodies from a reference run "
        "(PGS, " << kReferenceIterations << " iterations, S substeps, the run's push and friction "
        "model; S = reference_substeps, " << kReferenceSubsteps << " in the full sweep and "
     << kQuickReferenceSubsteps << " in the quick one) at the scene's trajectory time, given "
        "with its reason under each scene. A run that diverged before that time steps on to it "
        "(the physics alone) while its state stays finite. **The reference's own error** "
        "(reference_error_m) comes from the reference run at S / 4, S / 2 and S substeps "
        "(Richardson): with d1 its distance between S / 4 and S / 2 substeps and d2 = "
        "reference_check_m between S / 2 and S, the observed order is p = log2(d1 / d2) "
        "(reference_order) and the error d2 / (2^p - 1) "
        "(d2 itself for a first-order method, more where p is below 1). Where the distances do "
        "not shrink (p <= 0) the error is unknown. Trajectory errors under it, or with it "
        "unknown, are not resolved.\n"
     << "- **LCP residual (N)**: the natural-map residual |lambda - clamp(lambda - (A lambda - "
        "b) / A_jj, c_min, c_max)| over every row of every solve. A run that made no solve of "
        "A lambda = b has none (an empty cell): xpbd and avbd correct positions and solve per "
        "body, not this system, so they neither have nor rank on an LCP residual.\n"
     << "- **Substeps**: steps per 1/60 s frame (dt = 1 / (60 substeps) s); the iteration sweep "
        "runs at 1 substep, the substep sweep at 25 iterations.\n"
     << "- **Warm start** (column warm_start, dimensionless): each PGS row's lambda starts from "
        "this factor times its lambda of the previous step where its contact or rod persists "
        "(Sec. 6.2.3); 0 is the paper's cold start from 0. Every run above starts cold but the "
        "warm-started PGS iteration lines (1 substep), drawn in the same panels in their own "
        "colours; each scene's table \"Warm starting\" gives the fewest iterations with which "
        "PGS reaches the paper's error cold and warm, and the iterations saved.\n"
     << "- **Round-off floors** (diagrams only; tables and CSVs keep every value): " << kFloorNotes
     << "\n\n";
}

// A ranked value as report.md prints it: "never by the horizon" for +infinity (a run that never
// recovered), else the number.
std::string value_text(double v) { return std::isinf(v) ? std::string("never by the horizon") : number(v); }

// " (its own: 1/600 s)" where the scene's own dt (its world_def, what `cps simulate` steps
// with) is not the run's at 1 substep; "" otherwise or for a scene this build does not know.
std::string own_dt_note(const std::string& scene, const RunResult& r) {
  const scenes::Scene* s = scenes::find_scene(scene);
  if (!s || !r.dt_s || r.substeps != 1) return "";
  RunResult own;
  own.dt_s = s->world_def().dt;
  const std::string t = dt_text(own);
  return t == dt_text(r) ? std::string() : " (its own: " + t + ")";
}

// The settings of a run in one line: "jacobi, split, fixed, 25 it, 4 substeps, warm start 0.8"
// (the solver and the friction model only where its push reads them: "avbd, 25 it, 1 substep").
std::string settings_text(const RunResult& r) {
  const PushReads reads = r.reads();
  return (reads.solver ? r.solver + ", " : std::string()) + r.push + ", " +
         (reads.friction_model ? r.friction_model + ", " : std::string()) + std::to_string(r.iterations) +
         " it, " + std::to_string(r.substeps) + (r.substeps == 1 ? " substep" : " substeps") +
         (r.warm_start != 0.0 ? ", warm start " + shortest_decimal(r.warm_start) : std::string());
}

// Where run r solves A lambda = b with a method whose sweeps diverge on the paper run's sampled
// steps (solver_error_medians: the median relative force error above 1 at the largest sampled
// count up to r's iterations), a note that says so and what r's own solves left (its largest
// LCP residual); "" otherwise.
std::string diverging_solve_note(const RunResult& r,
                                 const std::map<std::string, std::map<int, double>>& solver_error) {
  const auto method = solver_error.find(r.solver);
  if (method == solver_error.end() || !r.reads().solver) return "";
  const std::pair<const int, double>* at = nullptr;
  for (const auto& entry : method->second) {
    if (entry.first <= r.iterations) at = &entry;
  }
  if (at == nullptr || !(at->second > 1.0)) return "";
  return " (but " + r.solver + "'s sweeps diverge on the paper run's steps: median force error " +
         number(at->second) + " |lambda*| at " + std::to_string(at->first) +
         " sweeps, under Solver error per step; this run's own solves ended with LCP residuals "
         "up to " + (r.residual_max_N ? number(*r.residual_max_N) + " N" : std::string("?")) + ")";
}

// The headline row of one scene: its measure at the paper's settings, their dt, and the cheapest
// run with at most half of it.
void write_headline_row(std::ostream& md, const std::string& scene, const Runs& runs,
                        const std::map<std::string, std::map<int, double>>& solver_error) {
  const std::string measure = primary_measure(scene);
  const RunResult* base = paper_run(runs);
  md << "| " << scene << " | " << label_of(measure) << " | ";
  if (!base || base->diverged || std::isnan(ranked_value(*base, measure))) {
    md << (base ? dt_text(*base) : std::string()) << " | "
       << (base ? "diverged or not measured" : "not in this sweep") << " | | | | |\n";
    return;
  }
  const double e0 = ranked_value(*base, measure);
  md << dt_text(*base) << own_dt_note(scene, *base) << " | " << value_text(e0);
  if (measure == "trajectory_error_m" && base->under_reference_error.value_or(false)) {
    md << (base->reference_error_m
               ? " (under its reference's own error, " + text(*base, "reference_error_m") + ")"
               : std::string(" (not resolved: its reference's own error is unknown)"));
  }
  md << " | " << time_text(*base) << " | ";
  const RunResult* best = cheapest_halving(runs, measure, *base);
  if (!best) {
    md << "none in this sweep | | |\n";
    return;
  }
  md << settings_text(*best) << " (dt " << dt_text(*best) << "): "
     << value_text(ranked_value(*best, measure)) << diverging_solve_note(*best, solver_error)
     << " | " << time_text(*best) << " | " << ratio_text(*best, *base) << " |\n";
}

// The headline: per scene, the paper's settings and the cheapest run with at most half their
// error; then why each scene's measure is the one it is.
void write_headline(std::ostream& md, const ReportContent& c) {
  md << "## Headline: the paper's settings and the cheapest run with at most half their error\n\n"
     << "Each scene's measure is one where smaller is better (why this one: under the table). "
        "The cheapest run (least time) whose value of it is at most half the value at the "
        "paper's settings, among every run of the scene (every solver, push, friction model, "
        "iteration and substep count), diverged runs left out (they are listed under "
        "[Omissions](#omissions)). A run that never recovers ranks after every run that does, "
        "so where the paper's run never recovers any run that does counts. For the trajectory "
        "error only the runs measured against the paper's run's reference count (its push and "
        "friction model: the reference is PGS at " << kReferenceIterations << " iterations and "
     << kReferenceSubsteps << " substeps (" << kQuickReferenceSubsteps << " in the quick sweep) "
        "of the run's own push and friction model, and the "
        "distances of runs of other pushes from their own references do not compare with it), "
        "and only if half the paper's value is above that reference's own error. The paper's "
        "settings are PGS, Baumgarte push, fixed friction, " << kPaperIterations
     << " iterations, cold start, one step per frame, at the dt the column gives: 1/60 s, the "
        "paper's, for the scenes of the paper (with the scene's own dt in brackets where "
        "`cps simulate` runs it at another), the scene's own dt for the others. Which run is "
        "the cheapest is decided by the medians of the times: where its time ratio's range "
        "(brackets) reaches 1, another run of the same error may be as cheap.\n\n"
     << "| scene | measure (smaller is better) | dt | at the paper's settings (PGS, Baumgarte, "
        "fixed friction, " << kPaperIterations << " it, 1 step per frame, cold) "
        "| its time (s/s) | cheapest run with at most half of it | its time (s/s) | time ratio |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (const std::string& scene : c.scenes) {
    const auto se = c.solver_error.find(scene);
    write_headline_row(md, scene, c.runs.at(scene),
                       se != c.solver_error.end() ? se->second
                                                  : std::map<std::string, std::map<int, double>>{});
  }
  md << "\nWhy each scene's measure:\n\n";
  for (const std::string& scene : c.scenes) {
    const scenes::Scene* s = scenes::find_scene(scene);
    md << "- **" << scene << "**: "
       << (s ? std::string(s->report.headline_reason)
             : "a scene this build does not know: the default measure, " +
                   std::string(scenes::ReportTraits{}.headline_reason))
       << ".\n";
  }
  md << "\n";
}

// The summary of the omissions: per scene, the runs the headline leaves out (diverged, without a
// value of the scene's measure or without a time), and the runs missing from a merge.
void write_omission_summary(std::ostream& md, const ReportContent& c) {
  md << "## Omissions\n\n"
     << "Runs the headline and the warm starting tables leave out: every run that diverged "
        "(drawn in the diagrams as a red x on the top edge, at its time until it diverged) and "
        "every run without a value of its scene's measure or without a time. Each scene's "
        "section lists them with their settings, when and why.";
  if (!c.missing.empty()) {
    md << " Besides them, " << c.missing.size() << " planned runs are missing from this report "
       << "(INCOMPLETE, above).";
  }
  md << "\n\n| scene | runs | diverged: not finite or far off | diverged: penetration past "
        "body size | diverged: rod error past body size | without a value or time |\n"
        "|---|---|---|---|---|---|\n";
  for (const std::string& scene : c.scenes) {
    const Runs& runs = c.runs.at(scene);
    int blown = 0, pen = 0, rod = 0, other = 0;
    for (const Omission& o : omissions(runs, primary_measure(scene))) {
      const std::string why = o.run->diverged_why.value_or("");
      if (!o.run->diverged) ++other;
      else if (why.rfind("penetration", 0) == 0) ++pen;
      else if (why.rfind("rod error", 0) == 0) ++rod;
      else ++blown;
    }
    md << "| " << scene << " | " << runs.size() << " | " << blown << " | " << pen << " | " << rod
       << " | " << other << " |\n";
  }
  md << "\n";
}

// A scene's omissions table: each run the headline leaves out, its settings, and when and why.
void write_omissions(std::ostream& md, const std::string& scene, const Runs& runs) {
  const std::vector<Omission> left = omissions(runs, primary_measure(scene));
  md << "### Omissions\n\n";
  if (left.empty()) {
    md << "None: every run of this scene finished with a value of its measure and a time.\n\n";
    return;
  }
  md << "| run | settings | dt | why left out |\n|---|---|---|---|\n";
  for (const Omission& o : left) {
    md << "| `" << o.run->id() << "` | " << settings_text(*o.run) << " | " << dt_text(*o.run)
       << " | " << o.why << " |\n";
  }
  md << "\n";
}

// The warm start factors of the warm table: 0, kReportWarmStarts and any other of the runs,
// ascending.
std::vector<double> warm_factors(const Runs& runs) {
  std::vector<double> factors = {0.0};
  for (const double w : kReportWarmStarts) factors.push_back(w);
  for (const RunResult* r : runs) {
    if (std::find(factors.begin(), factors.end(), r->warm_start) == factors.end()) {
      factors.push_back(r->warm_start);
    }
  }
  std::sort(factors.begin(), factors.end());
  return factors;
}

// The run with the fewest iterations at PGS, Baumgarte, fixed friction, 1 substep, warm start
// w, not diverged, whose `measure` is at most e0; nullptr if none.
const RunResult* fewest_reaching(const Runs& runs, double w, const std::string& measure, double e0) {
  const RunResult* fewest = nullptr;
  for (const RunResult* r : runs) {
    if (r->solver != "pgs" || r->push != "baumgarte" || r->friction_model != "fixed" ||
        r->substeps != 1 || r->warm_start != w || r->diverged) {
      continue;
    }
    if (!reaches(ranked_value(*r, measure), e0)) continue;
    if (!fewest || r->iterations < fewest->iterations) fewest = r;
  }
  return fewest;
}

// The table "Warm starting: what PGS needs to reach the paper's error" of one scene: for the
// cold start 0 and each warm start factor (warm_factors), the fewest iterations at the paper's
// other settings whose value of the scene's primary measure is at most the paper's run's (25
// iterations, cold); that run's time and its ratio to the paper's run's; and the iterations
// saved, 25 minus that count. "none in this sweep" where no run of the factor reaches it.
void write_warm_table(std::ostream& md, const std::string& scene, const Runs& runs) {
  const std::string measure = primary_measure(scene);
  md << "### Warm starting: what PGS needs to reach the paper's error\n\n";
  const RunResult* base = paper_run(runs);
  if (!base || base->diverged || std::isnan(ranked_value(*base, measure)) ||
      !(time_of(*base) > 0.0)) {
    md << "The paper's run (PGS, Baumgarte, fixed friction, " << kPaperIterations
       << " it, 1 substep, warm start 0) is "
       << (base ? "diverged or without a value of " + label_of(measure) : std::string("not in this sweep"))
       << ": nothing to compare with.\n\n";
    return;
  }
  const double e0 = ranked_value(*base, measure);
  md << "The fewest iterations at the paper's other settings (PGS, Baumgarte, fixed friction, "
        "1 substep) with which a run's " << label_of(measure) << " is at most the paper's run's ("
     << kPaperIterations << " it, warm start 0): " << value_text(e0) << ", in " << time_text(*base)
     << " s/s. Iterations saved: " << kPaperIterations << " minus that count. Diverged runs never "
        "count";
  md << (std::isinf(e0) ? "; the paper's run never recovers, so the table gives the fewest "
                          "iterations that do."
                        : ".");
  if (measure == "trajectory_error_m" && base->under_reference_error.value_or(false)) {
    md << " The paper's value is under its reference's own error ("
       << (base->reference_error_m
               ? number(*base->reference_error_m) + " m"
               : "unknown: its runs at a quarter, half and all of its " +
                     std::to_string(base->reference_substeps.value_or(kReferenceSubsteps)) +
                     " substeps do not converge")
       << "): the counts compare differences the reference does not resolve.";
  }
  md << "\n\n| warm start factor | fewest iterations | its " << label_of(measure)
     << " | its time (s/s) | time ratio to the paper's run | iterations saved |\n"
        "|---|---|---|---|---|---|\n";
  for (const double w : warm_factors(runs)) {
    md << "| " << shortest_decimal(w) << (w == 0.0 ? " (cold, the paper's)" : "") << " | ";
    const RunResult* fewest = fewest_reaching(runs, w, measure, e0);
    if (!fewest) {
      md << "none in this sweep | | | | |\n";
      continue;
    }
    md << fewest->iterations << " | " << value_text(ranked_value(*fewest, measure)) << " | "
       << time_text(*fewest) << " | " << ratio_text(*fewest, *base) << " | "
       << kPaperIterations - fewest->iterations << " |\n";
  }
  md << "\n";
}

// A scene's horizon and trajectory time with their reasons, and the references' own errors.
void write_scene_facts(std::ostream& md, const std::string& scene, const Runs& runs) {
  if (const scenes::Scene* s = scenes::find_scene(scene)) {
    // The quick sweep's horizon where its runs are the quick sweep's and it has one.
    const bool quick = std::any_of(runs.begin(), runs.end(),
                                   [](const RunResult* r) { return r->quick.value_or(false); });
    md << "- **Horizon** " << number(s->report_horizon_s(quick)) << " s: " << s->report.horizon_reason;
    if (quick && s->report.quick_horizon_s) {
      md << "; the quick sweep runs its first " << number(*s->report.quick_horizon_s)
         << " s (of " << number(s->report_horizon_s()) << " s), where its step costs the same";
    }
    md << ".\n- **Trajectory time** ";
    if (s->report.has_reference_solution) {
      md << s->report.trajectory_reason << ".";
    } else {
      md << number(std::min(s->report_trajectory_time_s(), s->report_horizon_s())) << " s: "
         << s->report.trajectory_reason << ".";
    }
    md << "\n";
  }
  std::map<std::string, std::string> checks;  // push, friction -> reference's own error
  for (const RunResult* r : runs) {
    const std::string check = text(*r, "reference_check_m");
    if (check.empty()) continue;
    checks[r->push + ", " + r->friction_model + " friction"] =
        (r->reference_error_m ? text(*r, "reference_error_m") : std::string("unknown")) +
        " (order " + (r->reference_order ? text(*r, "reference_order") : std::string("not measured")) +
        ", " + std::to_string(r->reference_substeps.value_or(kReferenceSubsteps) / 2) +
        " against " + std::to_string(r->reference_substeps.value_or(kReferenceSubsteps)) +
        " substeps " + check + ")";
  }
  if (checks.empty()) return;
  md << "- **The reference's own error** at the trajectory time (m):";
  bool first = true;
  for (const auto& [variant, value] : checks) {
    md << (first ? " " : "; ") << variant << ": " << value;
    first = false;
  }
  md << ".\n";
}

// One line of the convergence table: the runs of PGS, Baumgarte, fixed friction, cold, not
// diverged, with a value of `measure`, along substeps (at the paper's iterations) or along
// iterations (at 1 substep), by count ascending.
std::vector<std::pair<int, double>> convergence_line(const Runs& runs, const std::string& measure,
                                                     bool substeps) {
  std::map<int, double> line;
  for (const RunResult* r : runs) {
    if (r->solver != "pgs" || r->push != "baumgarte" || r->friction_model != "fixed" ||
        r->warm_start != 0.0 || r->diverged) {
      continue;
    }
    const double v = r->value(measure);
    if (!std::isfinite(v)) continue;
    if (substeps && r->iterations == kPaperIterations) line[r->substeps] = v;
    if (!substeps && r->substeps == 1) line[r->iterations] = v;
  }
  return {line.begin(), line.end()};
}

// The convergence table of a scene: for its trajectory error and its phase error (the measures
// against a reference), the local orders between successive runs of the paper's method along
// substeps and along iterations, and the reference's own order.
void write_convergence(std::ostream& md, const Runs& runs) {
  bool head = false;
  for (const char* measure : {"trajectory_error_m", "phase_error_deg"}) {
    for (const bool substeps : {true, false}) {
      const std::vector<std::pair<int, double>> line = convergence_line(runs, measure, substeps);
      if (line.size() < 2) continue;
      if (!head) {
        md << "**Convergence order** of the paper's method (PGS, Baumgarte, fixed friction, "
              "cold): between successive runs along the substeps (at " << kPaperIterations
           << " iterations) and along the iterations (at 1 substep), the local order log(e_a / "
              "e_b) / log(n_b / n_a) of the error e at n_a and n_b (1: the error halves when the "
              "count doubles; near 0: it no longer falls with that count, another error "
              "dominates: the other count's, or the reference's own).\n\n"
              "| measure | along | from | to | error from | error to | local order |\n"
              "|---|---|---|---|---|---|---|\n";
        head = true;
      }
      for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const auto [na, ea] = line[i];
        const auto [nb, eb] = line[i + 1];
        md << "| " << label_of(measure) << " | " << (substeps ? "substeps" : "iterations") << " | "
           << na << " | " << nb << " | " << number(ea) << " | " << number(eb) << " | "
           << number(local_order(ea, na, eb, nb)) << " |\n";
      }
    }
  }
  if (head) md << "\n";
  // The reference's own order (the same for every run of the paper's push and friction model).
  for (const RunResult* r : runs) {
    if (r->push != "baumgarte" || r->friction_model != "fixed" || !r->reference_check_m) continue;
    const int s = r->reference_substeps.value_or(kReferenceSubsteps);
    md << "The trajectory error's reference (PGS, " << kReferenceIterations << " iterations, "
       << "Baumgarte, fixed friction) at " << s / 4 << ", " << s / 2 << " and " << s
       << " substeps: order "
       << (r->reference_order ? number(*r->reference_order) : std::string("not measured"))
       << ", so its own error is "
       << (r->reference_error_m ? number(*r->reference_error_m) + " m"
                                : std::string("unknown (its distances do not shrink with dt)"))
       << " (" << number(*r->reference_check_m) << " m between " << s / 2 << " and " << s
       << " substeps).\n\n";
    break;
  }
}

// A run's quartiles of time, "Q1 to Q3", with the digits of its time; "" where it has none.
std::string quartiles_text(const RunResult& r) {
  const double q1 = r.value("cpu_s_per_sim_s_q1"), q3 = r.value("cpu_s_per_sim_s_q3");
  if (!std::isfinite(q1) || !std::isfinite(q3)) return "";
  const int digits = significant_digits(q1, time_of(r), q3);
  return number_with_digits(q1, digits) + " to " + number_with_digits(q3, digits);
}

// A run's least repeat's time with the digits of its median's; "" where it has none.
std::string least_time_text(const RunResult& r) {
  const double q1 = r.value("cpu_s_per_sim_s_q1"), q3 = r.value("cpu_s_per_sim_s_q3");
  const double least = r.value("cpu_s_per_sim_s_min");
  if (!std::isfinite(least)) return "";
  return number_with_digits(least, std::isfinite(q1) && std::isfinite(q3)
                                       ? significant_digits(q1, time_of(r), q3)
                                       : 3);
}

// A scene's table of runs: settings, time and its quartiles, its primary measure, residual, penetration, rod
// error, and when it diverged.
void write_run_table(std::ostream& md, const std::string& scene, const Runs& runs) {
  const std::string measure = primary_measure(scene);
  md << "| solver | push | friction | iterations | substeps | warm start | time (s/s) | "
        "time Q1 to Q3 (s/s) | least time (s/s) | "
     << label_of(measure)
     << " | under the reference's own error | residual RMS (N) | penetration max (m) | rod error "
        "max (m) | diverged at (s) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RunResult* r : runs) {
    md << "| " << r->solver << " | " << r->push << " | " << r->friction_model << " | "
       << r->iterations << " | " << r->substeps << " | " << shortest_decimal(r->warm_start)
       << " | " << time_text(*r) << " | " << quartiles_text(*r) << " | " << least_time_text(*r) << " | "
       << (std::isinf(ranked_value(*r, measure)) ? "never" : text(*r, measure)) << " | "
       << (r->under_reference_error ? (*r->under_reference_error ? "yes: not resolved" : "no") : "")
       << " | " << text(*r, "residual_rms_N") << " | " << text(*r, "penetration_max_m") << " | "
       << text(*r, "rod_error_max_m") << " | "
       << (r->diverged ? text(*r, "diverged_at_s") : "no") << " |\n";
  }
  md << "\n";
}

// One scene's section: its facts, the link to its CSV, the warm starting table, its diagrams
// and its runs.
void write_scene(std::ostream& md, const ReportContent& c, const std::string& scene) {
  const Runs& runs = c.runs.at(scene);
  const std::string stem = file_stem(scene);
  md << "## " << scene << "\n\n";
  write_scene_facts(md, scene, runs);
  md << "\nAll runs: [" << stem << ".csv](" << stem << ".csv).\n\n";
  write_convergence(md, runs);
  write_warm_table(md, scene, runs);
  const auto drawn = c.diagrams.find(scene);
  if (drawn != c.diagrams.end()) {
    for (const Measure* m : drawn->second) {
      md << "![" << scene << " " << m->column << "](" << stem << "_" << m->column << ".png)\n\n";
    }
  }
  if (const auto extra = c.scene_sections.find(scene); extra != c.scene_sections.end()) {
    md << extra->second;
  }
  write_run_table(md, scene, runs);
  write_omissions(md, scene, runs);
}

// "yes" when the overlap_m cell (m) is a number under kHoldingOverlapM, "no" when it is one at or
// above it, "-" when the cell is empty or not a number (a run that went non-finite).
std::string overlap_under_1cm(const std::string& overlap_m) {
  char* end = nullptr;
  const double v = std::strtod(overlap_m.c_str(), &end);
  if (overlap_m.empty() || end != overlap_m.c_str() + overlap_m.size() || !std::isfinite(v)) {
    return "-";
  }
  return v < kHoldingOverlapM ? "yes" : "no";
}

// The mass ratio section: how held is defined, and the table of mass_ratio.csv.
void write_mass_ratios(std::ostream& md, const CsvTable& pairs) {
  md << "## Mass ratios: does the stack hold?\n\n"
     << "A heavy cube (R kg) resting on a light one (1 kg), both of edge "
     << number(2.0 * scenes::kMassRatioHalfEdge) << " m, on the ground (stress scenes "
        "mass_ratio_R), started at rest and run for " << number(kPairSeconds)
     << " s at 60 Hz with 25 iterations. **Held** means the light cube is still between the "
        "heavy cube and the ground: its centre within its half edge ("
     << number(scenes::kMassRatioHalfEdge) << " m) of the heavy cube's vertical axis, so the "
        "heavy cube's centre of mass is over its top face, and the heavy cube's centre within "
     << number(kHeldHeightTolerance) << " m of its stacked height " << number(kStackedHeight)
     << " m (squeezed out, it drops to " << number(scenes::kMassRatioHalfEdge)
     << " m). Each criterion has its own column: stacked (the two above) and overlap under 1 cm "
        "at 25 iterations, then the iteration counts among 1, 2, 4, ..., 256 (25 is not one of "
        "them) with which the same run meets both (meeting them need not grow with the count). "
        "All in [mass_ratio.csv](mass_ratio.csv).\n\n"
     << "| mass ratio | solver | push | stacked at 25 it | overlap under 1 cm at 25 it | heavy "
        "cube height (m) | light cube off the heavy one's axis (m) | deepest overlap (m) | "
        "iterations of 1 to 256 that give both |\n|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < pairs.rows.size(); ++i) {
    const auto cell = [&](const char* column) { return pairs.cell(i, column); };
    md << "| " << cell("mass_ratio") << " | " << cell("solver") << " | " << cell("push") << " | "
       << (cell("held") == "1" ? "yes" : "no") << " | " << overlap_under_1cm(cell("overlap_m"))
       << " | " << cell("heavy_height_m") << " | "
       << cell("light_offset_m") << " | " << cell("overlap_m") << " | "
       << (cell("iterations_holding").empty() ? std::string("none") : cell("iterations_holding"))
       << " |\n";
  }
  md << "\n";
}

}  // namespace

std::string report_markdown(const ReportContent& content) {
  std::ostringstream md;
  md << "# Error against run time\n\n";
  if (!content.missing.empty()) write_missing(md, content);
  write_definitions(md, content);
  write_headline(md, content);
  write_omission_summary(md, content);
  for (const std::string& scene : content.scenes) write_scene(md, content, scene);
  write_mass_ratios(md, content.pairs);
  return md.str();
}

}  // namespace cps::cli
