// `cps report push`: the push methods side by side (see push/report.h): the cases run per
// method (push/cases.h), then push.csv, push.md and the diagrams written from their results.
#include "report/push/report.h"
#include "report/push/scorecard.h"

#include "divergence.h"
#include "options/progress.h"
#include "output/atomic_file.h"
#include "output/output.h"
#include "report/gnuplot.h"
#include "report/mass_ratio.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// The diagrams' floors: values under them are drawn on them (log axes cannot show 0).
constexpr double kOverlapFloor = 1e-6;  // m
constexpr double kSpeedFloor = 1e-4;    // m/s

// The columns of push.csv, in order; each carries its unit as a suffix (_s, _m, _mps, _J,
// _rel: a ratio, us_per_step: microseconds); push, case and the mass ratios have none.
// variant: "" at the scene's settings, else the parameter set besides push (a tuned row);
// iterations: the solver's sweeps per solve (a count).
const std::vector<std::string> kColumns = {
    "push", "case", "variant", "seconds_s", "dt_s", "iterations", "diverged_at_s",
    "overlap_under_1mm_from_s", "max_overlap_m", "peak_speed_mps", "energy_injected_J",
    "final_height_error_m", "final_heights_m", "rest_heights_m", "max_drift_m",
    "slide_off_time_s", "mass_ratios_held", "largest_mass_ratio_held", "max_rod_error_m",
    "max_rod_error_rel", "max_phase_error_deg", "arrival_s", "survival_s",
    "final_displacement_m", "leave_distance_m", "max_penetration_m", "max_rod_stretch_m",
    "us_per_step", "timed_from_s", "timed_for_s"};

// Cell texts for times that did not happen and ratios that did not hold.
constexpr const char* kNever = "never";
constexpr const char* kNone = "none";

std::string numbers(const std::vector<double>& values) {
  std::string s;
  for (const double v : values) {
    if (!s.empty()) s += ' ';
    s += number(v);
  }
  return s;
}

// One row of push.csv being filled: a cell per column of kColumns, "" until set.
struct PushRow {
  std::vector<std::string> cells = std::vector<std::string>(kColumns.size());

  PushRow(const std::string& push, const std::string& kase, double seconds, double dt,
          const std::optional<double>& diverged_at) {
    set("push", push);
    set("case", kase);
    set("seconds_s", number(seconds));
    set("dt_s", number(dt));
    if (diverged_at) set("diverged_at_s", number(*diverged_at));
  }
  void set(std::string_view column, std::string text) {
    const auto it = std::find(kColumns.begin(), kColumns.end(), column);
    cells[static_cast<std::size_t>(it - kColumns.begin())] = std::move(text);
  }
};

// The row of a column case (the intersecting stack, sphere_in_box).
PushRow column_row(const Method& m, const char* kase, const ColumnResult& c) {
  PushRow r(m.name, kase, c.seconds, c.dt, c.diverged_at);
  r.set("overlap_under_1mm_from_s", c.resolved_at ? number(*c.resolved_at) : kNever);
  r.set("max_overlap_m", number(c.max_overlap_m));
  r.set("peak_speed_mps", number(c.peak_speed_mps));
  r.set("energy_injected_J", number(c.energy_injected_J));
  r.set("final_height_error_m", number(c.height_error_m));
  r.set("final_heights_m", numbers(c.final_heights));
  r.set("rest_heights_m", numbers(c.rest));
  return r;
}

// The row of a case run for its metrics (the stack, the pendulums).
PushRow metrics_row(const Method& m, const char* kase, const MetricsResult& r) {
  return PushRow(m.name, kase, r.seconds, r.dt, r.diverged_at);
}

// The label of a hard case's row in push.md: the method's, and for a tuned row what was set.
std::string hard_label(const Method& m, const HardResult& h) {
  if (h.variant.empty()) return m.label;
  return m.name + " with " + h.variant + " (tuned variant, not the scene's settings)";
}

// The us per step (CPU time of this thread in World::step) of a hard case.
double hard_us_per_step(const HardResult& h) {
  return h.steps ? 1e6 * h.step_cpu_s / static_cast<double>(h.steps) : std::nan("");
}

// True for a case whose bodies' masses differ (the heavy cases): only there is a mass ratio held.
bool unequal_masses(const HardResult& h) { return metric(h.metrics, "mass_ratio") > 1.0; }

// The row of a hard case (HardCaseMetrics' keys).
PushRow hard_row(const Method& m, const HardResult& h) {
  PushRow r(m.name, h.scene, h.seconds, h.dt, h.diverged_at);
  r.set("variant", h.variant);
  r.set("iterations", std::to_string(h.iterations));
  const nlohmann::json& j = h.metrics;
  r.set("arrival_s", j.contains("arrival_s") && j["arrival_s"].is_number() ? number(metric(j, "arrival_s")) : kNever);
  r.set("survival_s", h.held_throughout() ? kNever : number(metric(j, "survival_s")));
  r.set("final_displacement_m", number(metric(j, "final_displacement_m")));
  r.set("leave_distance_m", number(metric(j, "leave_distance_m")));
  r.set("max_penetration_m", number(metric(j, "max_penetration_m")));
  r.set("energy_injected_J", number(metric(j, "energy_injected_J")));
  if (h.has_rods) r.set("max_rod_stretch_m", number(metric(j, "max_rod_stretch_m")));
  if (unequal_masses(h)) r.set("largest_mass_ratio_held", h.held_throughout() ? number(metric(j, "mass_ratio")) : kNone);
  r.set("us_per_step", number(hard_us_per_step(h)));
  r.set("timed_from_s", "0");
  r.set("timed_for_s", number(static_cast<double>(h.steps) * h.dt));
  return r;
}

// The rows of one method, in the order of its cases.
std::vector<PushRow> rows_of(const PushPlan& plan, const MethodResults& r) {
  PushRow is = column_row(r.method, "intersecting_stack", r.intersecting);
  is.set("us_per_step", number(r.intersecting_us));
  is.set("timed_from_s", number(plan.intersecting->bench.start_s));
  is.set("timed_for_s", number(plan.intersecting->bench.seconds));
  PushRow stack = metrics_row(r.method, "stack", r.stack);
  stack.set("max_drift_m", number(metric(r.stack.metrics, "max_drift_m")));
  const double slide = metric(r.stack.metrics, "slide_off_time_s");
  stack.set("slide_off_time_s", std::isnan(slide) ? kNever : number(slide));
  stack.set("us_per_step", number(r.stack.steps ? 1e6 * r.stack.step_cpu_s / static_cast<double>(r.stack.steps)
                                                : std::nan("")));
  stack.set("timed_from_s", "0");
  stack.set("timed_for_s", number(static_cast<double>(r.stack.steps) * r.stack.dt));
  PushRow pair(r.method.name, "mass_ratio", kPairSeconds, scenes::mass_ratio_world_def().dt, std::nullopt);
  pair.set("mass_ratios_held", r.held.empty() ? kNone : numbers(r.held));
  pair.set("largest_mass_ratio_held", r.held.empty() ? kNone : number(r.held.back()));
  PushRow grid = metrics_row(r.method, "pendulum_grid", r.grid);
  grid.set("max_rod_error_m", number(metric(r.grid.metrics, "max_rod_error_m")));
  PushRow wave = metrics_row(r.method, "pendulum_wave", r.wave);
  wave.set("max_rod_error_rel", number(metric(r.wave.metrics, "max_rod_error_rel")));
  wave.set("max_phase_error_deg", number(metric(r.wave.metrics, "max_phase_error_deg")));
  pair.set("iterations", std::to_string(kPairIterations));
  std::vector<PushRow> rows = {is, column_row(r.method, "sphere_in_box", r.sphere), stack, pair, grid, wave};
  for (const HardResult& h : r.hard) rows.push_back(hard_row(r.method, h));
  return rows;
}

// A cell of push.md: push.csv's cell of the method's case (and variant, "" at the scene's
// settings), "-" where it is empty (does not
// apply, not measured), and "diverged at T s" for the measures of a case that diverged.
std::string md_cell(const CsvTable& csv, const std::string& push, const std::string& kase,
                    const std::string& column, const std::string& variant = "") {
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    if (csv.cell(i, "push") != push || csv.cell(i, "case") != kase || csv.cell(i, "variant") != variant) continue;
    const std::string& diverged = csv.cell(i, "diverged_at_s");
    if (!diverged.empty()) return "diverged at " + diverged + " s";
    const std::string& cell = csv.cell(i, column);
    return cell.empty() ? "-" : cell;
  }
  return "-";
}

// The legend of push.md: what each column is, precisely.
std::string legend(const PushPlan& p) {
  const bool quick = p.quick;
  const double stack_seconds = p.stack_seconds, grid_seconds = p.grid_seconds, wave_seconds = p.wave_seconds;
  const scenes::Scene &is = *p.intersecting, &grid = *p.grid, &wave = *p.wave;
  std::ostringstream md;
  md << "Every push method of this build (the choices of the world parameter push, `--push NAME`) "
        "runs the same cases, each at the scene's own settings with only push changed"
     << (quick ? "; **--quick**: the stack over " + number(stack_seconds) +
                     " s instead of 600 s, the pendulum wave over " + number(wave_seconds) +
                     " s instead of its " + number(wave.default_seconds) + " s"
               : std::string())
     << ". \"-\": the measure does not apply; \"never\": the time was not reached; "
        "\"diverged at T s\": at T the state stopped being finite or passed 1e6 m or 1e6 m/s, "
        "or a contact was deeper than the smallest size of a body it touches for "
     << scenes::kDivergedSteps << " steps in a row from T (as `cps simulate` flags it), and the "
        "case's measures stop there.\n\n"
     << "- **IS** is the intersecting stack (Sec. 10.2: five cubes of half extent 1.2 m started "
        "0.4 m overlapping, the bottom one 1.2 m into the ground), **SiB** the stress scene "
        "sphere_in_box (a ball of radius 0.4 m started 0.7 m into a box of half extent 1 m "
        "resting on the ground), each run " << number(kColumnSeconds) << " s at 60 Hz.\n"
     << "- **< 1 mm from (s)**: the first time t from which the largest overlap stays under "
        "1 mm to the end of the run. The largest overlap of the state at time t is the deepest "
        "contact over World::manifolds() of the step that starts from it (the last state: the "
        "same narrow phase on every pair).\n"
     << "- **peak speed (m/s)**: the largest speed of any body's centre of mass over the run, "
        "after step 0.\n"
     << "- **energy injected (J)**: max over t of (KE + PE) minus the PE of the column at rest; KE "
        "translational and rotational, PE = -m g . x summed over the bodies. At rest: the bodies "
        "stacked on the ground in their order without overlap (IS: cube centres at 1.2, 3.6, "
        "6.0, 8.4, 10.8 m; SiB: box centre at 1.0 m, ball centre at 2.0 + 0.4 m), computed from "
        "the bodies' masses, shapes and gravity. Negative: the run never reached the resting "
        "state's energy.\n"
     << "- **height error (m)**: the largest |final height - resting height| of a body centre; "
        "push.csv has the heights (final_heights_m, rest_heights_m).\n"
     << "- **stack drift (m)**, **stack slides off (s)**: the stack scene (Sec. 10.1) over "
     << number(stack_seconds) << " s" << (quick ? " (--quick; 600 s without it)" : "")
     << ": its metrics max_drift_m (the largest horizontal distance of a cube centre from the "
        "column's axis) and slide_off_time_s (the first time a cube's centre is 0.5 m off the "
        "axis or it tilts past 10 degrees).\n"
     << "- **mass ratio held**: the largest mass ratio R of ";
  for (std::size_t i = 0; i < std::size(kMassRatios); ++i) {
    md << (i ? ", " : "") << number(kMassRatios[i]);
  }
  md << " (the report's mass ratio table: a cube of R kg resting on one of 1 kg on the ground) "
        "whose pair still holds after "
     << number(kPairSeconds) << " s with PGS at " << kPairIterations
     << " iterations (the light cube's centre within its half edge of the heavy cube's axis and "
        "the heavy cube within a quarter edge of its stacked height); \"none\": none held.\n"
     << "- **grid rod error (m)**: the pendulum grid's metric max_rod_error_m over "
     << number(grid_seconds) << " s (its default " << number(grid.default_seconds)
     << " s): the largest |rod length - its length| over the run. **wave rod error**, **wave phase error "
        "(deg)**: the pendulum wave's metrics max_rod_error_rel (the largest |rod length - "
        "its length| / its length over the run) and max_phase_error_deg (the largest phase error "
        "over the run and its 50 pendulums against the reduced-coordinate reference: the angle "
        "of a swing in the plane (angle, -rate / w), sampled every 0.02 s and unwrapped, so it "
        "is not bounded by the amplitude), run "
     << number(wave_seconds) << " s"
     << (wave_seconds < wave.default_seconds
             ? " (--quick; its default is " + number(wave.default_seconds) + " s)"
             : std::string(" (its default)"))
     << ".\n"
     << "- **IS us/step**, **stack us/step**: microseconds per step, CPU time of the stepping thread around "
        "World::step only (metrics and bookkeeping outside): IS over its first "
     << number(is.bench.seconds) << " s (the median of " << kCostRepeats
     << " runs after one untimed), the stack over its whole run. A measurement on this machine "
        "at the time of the run, not a property of the method.\n";
  return md.str();
}

// ---- The hard cases' sections of push.md ----

// A number in a sentence: 3 significant digits (printf "%.3g").
std::string brief(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

// "a", "a and b", "a, b and c".
std::string name_list(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t k = 0; k < names.size(); ++k) {
    s += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  }
  return s;
}

// One row of a hard case's section: the method, its result, and its label in push.md.
struct HardRow {
  const Method* method = nullptr;
  const HardResult* result = nullptr;
  std::string label;
};

// The rows of the case `scene`: every method at the scene's settings in the table's order, then
// the tuned rows.
std::vector<HardRow> hard_rows(const std::vector<MethodResults>& results, const std::string& scene) {
  std::vector<HardRow> rows;
  for (const bool tuned : {false, true}) {
    for (const MethodResults& r : results) {
      for (const HardResult& h : r.hard) {
        if (h.scene == scene && h.variant.empty() != tuned) rows.push_back({&r.method, &h, hard_label(r.method, h)});
      }
    }
  }
  return rows;
}

// The name of a row in a sentence: the method's, and the variant of a tuned row.
std::string row_name(const HardRow& r) {
  return r.result->variant.empty() ? r.method->name : r.method->name + " (" + r.result->variant + ")";
}

// The row with the largest (or, `smallest`, the smallest) `key` among the rows that did not
// diverge; nullptr if none.
const HardRow* extreme(const std::vector<HardRow>& rows, const char* key, bool smallest) {
  const HardRow* best = nullptr;
  for (const HardRow& r : rows) {
    if (r.result->diverged_at) continue;
    const double v = metric(r.result->metrics, key);
    if (std::isnan(v)) continue;
    const double b = best ? metric(best->result->metrics, key) : 0.0;
    if (!best || (smallest ? v < b : v > b)) best = &r;
  }
  return best;
}

// What a hard case's table shows, in sentences computed from its rows: which rows held for the
// whole run, when the others left their places (or diverged), what the tuned avbd row changes,
// the deepest contact, the rod stretch (with rods), the energy injected and the cost.
std::string hard_findings(const HardCase& c, const std::vector<HardRow>& rows) {
  const HardResult& any = *rows.front().result;
  const double seconds = c.seconds;
  std::vector<std::string> held, diverged;
  std::vector<const HardRow*> left, never_arrived;
  for (const HardRow& r : rows) {
    const HardResult& h = *r.result;
    if (h.diverged_at) {
      diverged.push_back(row_name(r) + " at " + brief(*h.diverged_at) + " s");
    } else if (h.held_throughout()) {
      held.push_back(row_name(r));
    } else if (!h.metrics.contains("arrival_s") || !h.metrics["arrival_s"].is_number()) {
      never_arrived.push_back(&r);
    } else {
      left.push_back(&r);
    }
  }
  std::ostringstream s;
  s << "**What it shows** (from the numbers above): ";
  if (held.empty()) {
    s << "no row keeps every body within " << brief(metric(any.metrics, "leave_distance_m"))
      << " m of its place for the whole " << brief(seconds) << " s at " << any.iterations
      << " iterations";
  } else {
    s << name_list(held) << (held.size() == 1 ? " keeps" : " keep") << " every body within "
      << brief(metric(any.metrics, "leave_distance_m")) << " m of its place for the whole "
      << brief(seconds) << " s at " << any.iterations << " iterations";
  }
  if (!left.empty()) {
    std::stable_sort(left.begin(), left.end(), [](const HardRow* a, const HardRow* b) {
      return metric(a->result->metrics, "survival_s") < metric(b->result->metrics, "survival_s");
    });
    const HardRow &first = *left.front(), &last = *left.back();
    const double t_first = metric(first.result->metrics, "survival_s");
    if (left.size() > 1 && t_first == metric(last.result->metrics, "survival_s")) {
      s << "; " << (left.size() == rows.size() ? "every row loses" : std::to_string(left.size()) + " rows lose")
        << " it, all at " << brief(t_first) << " s";
    } else if (left.size() == 1) {
      s << "; " << row_name(first) << " loses it at " << brief(metric(first.result->metrics, "survival_s")) << " s";
    } else {
      s << "; " << left.size() << " rows lose it, first " << row_name(first) << " at "
        << brief(metric(first.result->metrics, "survival_s")) << " s, last " << row_name(last)
        << " at " << brief(metric(last.result->metrics, "survival_s")) << " s";
    }
  }
  if (!never_arrived.empty()) {
    std::vector<std::string> names;
    for (const HardRow* r : never_arrived) names.push_back(row_name(*r));
    s << "; under " << name_list(names) << " the bodies never reach their places";
  }
  if (!diverged.empty()) s << "; diverged: " << name_list(diverged);
  s << ".";
  // The tuned row against the same method at the scene's settings.
  for (const HardRow& t : rows) {
    if (t.result->variant.empty()) continue;
    for (const HardRow& d : rows) {
      if (d.method != t.method || !d.result->variant.empty()) continue;
      const auto fate = [](const HardResult& h) {
        if (h.diverged_at) return "diverges at " + brief(*h.diverged_at) + " s";
        if (h.held_throughout()) return std::string("holds");
        return "fails at " + brief(metric(h.metrics, "survival_s")) + " s";
      };
      s << " " << t.method->name << " at the scene's settings " << fate(*d.result) << "; with "
        << t.result->variant << " it " << fate(*t.result) << ".";
    }
  }
  if (const HardRow* deep = extreme(rows, "max_penetration_m", false)) {
    const HardRow* shallow = extreme(rows, "max_penetration_m", true);
    s << " Deepest contact: " << brief(metric(deep->result->metrics, "max_penetration_m")) << " m ("
      << row_name(*deep) << "), the least " << brief(metric(shallow->result->metrics, "max_penetration_m"))
      << " m (" << row_name(*shallow) << ").";
  }
  if (any.has_rods) {
    if (const HardRow* most = extreme(rows, "max_rod_stretch_m", false)) {
      const HardRow* least = extreme(rows, "max_rod_stretch_m", true);
      s << " Rods stretch up to " << brief(metric(most->result->metrics, "max_rod_stretch_m"))
        << " m (" << row_name(*most) << "), the least " << brief(metric(least->result->metrics, "max_rod_stretch_m"))
        << " m (" << row_name(*least) << ").";
    }
  }
  if (const HardRow* most = extreme(rows, "energy_injected_J", false)) {
    const double e = metric(most->result->metrics, "energy_injected_J");
    if (e > 0.0) {
      s << " The most energy injected: " << brief(e) << " J (" << row_name(*most) << ").";
    } else {
      s << " No row that stayed finite raised the energy above its reference (0 J injected).";
    }
  }
  const HardRow *cheap = nullptr, *dear = nullptr;
  for (const HardRow& r : rows) {
    const double us = hard_us_per_step(*r.result);
    if (std::isnan(us)) continue;
    if (!cheap || us < hard_us_per_step(*cheap->result)) cheap = &r;
    if (!dear || us > hard_us_per_step(*dear->result)) dear = &r;
  }
  if (cheap) {
    s << " A step costs " << brief(hard_us_per_step(*cheap->result)) << " us (" << row_name(*cheap)
      << ") to " << brief(hard_us_per_step(*dear->result)) << " us (" << row_name(*dear) << ").";
  }
  return s.str();
}

// The legend of the hard cases' sections.
std::string hard_legend(const PushPlan& p) {
  std::ostringstream md;
  md << "## The hard cases\n\n"
     << "Stress scenes where convergence, not stability, decides, each run at its own settings "
        "(the paper's: dt = 1/60 s, PGS at the scene's iterations) with only push changed, and "
        "measured by its own metrics (HardCaseMetrics: `cps simulate NAME --json`). Each body has "
        "a resting place (where it stands as built, or the column it lands in) and leaves it when "
        "its centre is farther than the case's leave distance from it. A row \"";
  md << kTunedMethod << " with avbd_k_start=" << number(kTunedAvbdKStart)
     << "\" is a tuned variant, not the scene's settings: avbd's penalties start at "
     << number(kTunedAvbdKStart) << " N/m instead of its default; the row above it is avbd as "
        "every other method runs.";
  bool quick_long = false;
  for (const HardCase& c : p.hard) quick_long |= c.seconds < c.scene->default_seconds;
  if (quick_long) {
    md << " **--quick**: the 10,000-step cases run " << kQuickLongRunSteps << " steps ("
       << number(kQuickLongRunSteps * p.hard.back().scene->world_def().dt) << " s); the full report runs all 10,000.";
  }
  md << "\n\n"
     << "- **survival (s)**: the time from which a body stays out of its place for 0.5 s, after "
        "every body had arrived (survival_s; a body that sags out and comes back within 0.5 s "
        "has not left); **never**: no body left its place, held to the end of the run; 0 with "
        "arrival \"never\": the bodies never arrived; a diverged run survives until it "
        "diverged.\n"
     << "- **arrival (s)**: the first time from which every body stays within the leave distance "
        "of its place for 0.5 s (0 for a scene built at rest).\n"
     << "- **final displacement (m)**: the largest distance of a body from its place at the end.\n"
     << "- **max penetration (m)**: the deepest contact of any step.\n"
     << "- **energy injected (J)**: the largest rise of KE + PE above the larger of the start's "
        "and the resting places' energy; a collapse lowers E and can hide energy made at the "
        "same time, so 0 means no rise, not that nothing was made.\n"
     << "- **max rod stretch (m)**: the largest |distance - length| of any rod at any step "
        "(scenes with rods).\n"
     << "- **mass ratio held** (the cases of unequal masses): the scene's heaviest movable mass "
        "over its lightest when the row held for the whole run (survival \"never\"), at the "
        "iterations stated; \"none\" when it did not.\n"
     << "- **us/step**: microseconds of CPU time of the stepping thread (CLOCK_THREAD_CPUTIME_ID) "
        "in World::step alone, per step over the whole run: a measurement on this machine at the "
        "time of the run.\n";
  return md.str();
}

// The section of one hard case: what ran, the table (from push.csv) and what it shows.
std::string hard_section(const HardCase& c, const CsvTable& csv, const std::vector<MethodResults>& results) {
  const std::string scene(c.scene->name);
  const std::vector<HardRow> rows = hard_rows(results, scene);
  if (rows.empty()) return "";
  const HardResult& any = *rows.front().result;
  const bool heavy = unequal_masses(any);
  std::ostringstream md;
  md << "### " << scene << "\n\n"
     << c.scene->summary << ". Run " << number(c.seconds) << " s ("
     << static_cast<long long>(std::llround(c.seconds / any.dt)) << " steps of " << number(any.dt)
     << " s" << (c.seconds < c.scene->default_seconds ? "; --quick, its default is " + number(c.scene->default_seconds) + " s" : "")
     << ") at " << any.iterations << " iterations; leave distance "
     << number(metric(any.metrics, "leave_distance_m")) << " m.\n\n"
     << "| method | survival (s) | arrival (s) | final displacement (m) | max penetration (m) | "
        "energy injected (J) | " << (any.has_rods ? "max rod stretch (m) | " : "")
     << (heavy ? "mass ratio held | " : "") << "us/step |\n|---|---|---|---|---|---|"
     << (any.has_rods ? "---|" : "") << (heavy ? "---|" : "") << "---|\n";
  for (const HardRow& r : rows) {
    const auto cell = [&](const char* column) {
      return md_cell(csv, r.method->name, scene, column, r.result->variant);
    };
    md << "| " << r.label;
    for (const char* column : {"survival_s", "arrival_s", "final_displacement_m", "max_penetration_m", "energy_injected_J"}) {
      md << " | " << cell(column);
    }
    if (any.has_rods) md << " | " << cell("max_rod_stretch_m");
    if (heavy) md << " | " << cell("largest_mass_ratio_held");
    md << " | " << cell("us_per_step") << " |\n";
  }
  md << "\n" << hard_findings(c, rows) << "\n\n";
  return md.str();
}

// push.md: the legend and one row per method, then a section per hard case (elapsed: the whole
// run's wall time, s).
std::string push_markdown(const PushPlan& p, const CsvTable& csv, const std::vector<MethodResults>& results,
                          double elapsed) {
  std::ostringstream md;
  md << "# Push methods side by side\n\n"
     << "Made by `cps report push" << (p.quick ? " --quick" : "") << "` (" << p.methods.size()
     << " methods, " << number(elapsed) << " s on this machine); every value in "
     << "[push.csv](push.csv).\n\n"
     << legend(p) << "\n"
     << "| method | IS < 1 mm from (s) | IS peak speed (m/s) | IS energy injected (J) | IS height "
        "error (m) | SiB < 1 mm from (s) | SiB peak speed (m/s) | SiB energy injected (J) | SiB "
        "height error (m) | stack drift (m) | stack slides off (s) | mass ratio held | grid rod "
        "error (m) | wave rod error (rel) | wave phase error (deg) | IS us/step | stack us/step "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Method& m : p.methods) {
    const auto c = [&](const char* kase, const char* column) { return md_cell(csv, m.name, kase, column); };
    md << "| " << m.label;
    for (const char* kase : {"intersecting_stack", "sphere_in_box"}) {
      for (const char* column : {"overlap_under_1mm_from_s", "peak_speed_mps",
                                 "energy_injected_J", "final_height_error_m"}) {
        md << " | " << c(kase, column);
      }
    }
    md << " | " << c("stack", "max_drift_m") << " | " << c("stack", "slide_off_time_s") << " | "
       << c("mass_ratio", "largest_mass_ratio_held") << " | "
       << c("pendulum_grid", "max_rod_error_m") << " | "
       << c("pendulum_wave", "max_rod_error_rel") << " | "
       << c("pendulum_wave", "max_phase_error_deg") << " | "
       << c("intersecting_stack", "us_per_step") << " | " << c("stack", "us_per_step") << " |\n";
  }
  md << "\n![largest overlap against time](push_overlap.png)\n\n"
     << "![largest body speed against time](push_speed.png)\n";
  if (!p.hard.empty()) {
    md << "\n" << hard_legend(p) << "\n";
    for (const HardCase& c : p.hard) md << hard_section(c, csv, results);
  }
  return md.str();
}

// The diagrams' data: per case (IS, SiB) per method an index block "t overlap speed"; and the
// largest overlap (m) and speed (m/s) in it (at least the floors), and the longest run (s).
struct SeriesData {
  std::string text;
  double overlap_max = kOverlapFloor, speed_max = kSpeedFloor, t_max = 0.0;
};

SeriesData series_data(const PushPlan& p, const std::vector<MethodResults>& results) {
  SeriesData d;
  std::ostringstream data;
  data << "# t (s), largest overlap (m), largest body speed (m/s); a block per case "
          "(intersecting_stack, sphere_in_box) and method (";
  for (std::size_t k = 0; k < p.methods.size(); ++k) data << (k ? ", " : "") << p.methods[k].name;
  data << ")\n";
  for (const bool sphere : {false, true}) {
    for (const MethodResults& r : results) {
      const ColumnResult& c = sphere ? r.sphere : r.intersecting;
      for (const Sample& s : c.series) {
        data << s.t << " " << s.overlap_m << " " << s.speed_mps << "\n";
        d.overlap_max = std::max(d.overlap_max, s.overlap_m);
        d.speed_max = std::max(d.speed_max, s.speed_mps);
      }
      d.t_max = std::max(d.t_max, c.seconds);
      data << "\n\n";
    }
  }
  d.text = data.str();
  return d;
}

// One diagram: a panel per case (IS, SiB), a line per method, value against time, log y with
// values under `floor` drawn on it. `column` 1: overlap, 2: speed (in the data file's order).
std::string diagram_script(const fs::path& data, const std::vector<Method>& ms, int column,
                           const std::string& title, const std::string& axis, double floor,
                           double y_max, double t_max, bool threshold) {
  static const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                         "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
  std::ostringstream gp;
  gp << "set multiplot layout 1,2 title " << gp_text(title) << " font ',12'\n"
     << "set logscale y\nset format y '1e%T'\nset grid xtics ytics lc rgb '#d8d8d8'\n"
     << "set xrange [0:" << t_max << "]\nset yrange [" << floor / 2.0 << ":" << y_max * 3.0
     << "]\nset xlabel 'time (s)'\nset ylabel " << gp_text(axis)
     << "\nset key top right font ',8' opaque\nset tics font ',8'\n";
  if (threshold) {
    gp << "set arrow 1 from graph 0, first " << kResolvedOverlap << " to graph 1, first "
       << kResolvedOverlap << " nohead dt 2 lw 1.2 lc rgb 'gray30' back\n"
       << "set label 1 '1 mm' at graph 0.01, first " << kResolvedOverlap
       << " offset 1,0.6 font ',8' tc rgb 'gray30'\n";
  }
  const char* const panels[] = {"intersecting stack", "sphere in box"};
  for (int p = 0; p < 2; ++p) {
    gp << "set title " << gp_text(panels[p]) << " font ',10'\nplot ";
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const std::size_t index = static_cast<std::size_t>(p) * ms.size() + k;
      gp << (k ? ", \\\n     " : "") << gp_text(data.string()) << " index " << index
         << " using 1:($" << column + 1 << " < " << floor << " ? " << floor << " : $"
         << column + 1 << ") with lines lw 1.6 lc rgb '"
         << kColours[k % (sizeof kColours / sizeof kColours[0])] << "' title "
         << gp_text(ms[k].name);
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

// Writes OUT/plots/STEM.dat and .gp, OUT/STEM.png and OUT/STEM.pdf (gnuplot's pdfcairo terminal:
// its text is text, for a paper), each through a temporary of this run.
void write_diagram(const fs::path& out, const std::string& stem, const std::string& data_text,
                   const std::string& body) {
  write_text_atomic(out / "plots" / (stem + ".dat"), data_text);
  // The PDF at 100 pixels of the PNG per inch, so its 10 pt text sits as in the PNG.
  draw_pictures(out / "plots" / (stem + ".gp"),
                {{out / (stem + ".png"), "set terminal pngcairo size 1100,480 font ',10' noenhanced"},
                 {out / (stem + ".pdf"), "set terminal pdfcairo size 11in,4.8in font ',10' noenhanced"}},
                body, {"reset\n", "unset output\n", ""});
}

// The cases run_methods runs, over every method.
long long case_count(const PushPlan& plan) {
  long long n = 0;
  for (const Method& m : plan.methods) n += push_case_count(plan, m);
  return n;
}

// Runs every method of the plan, with progress on stderr.
std::vector<MethodResults> run_methods(const PushPlan& plan) {
  std::vector<MethodResults> results;
  Progress progress(std::string("report push") + (plan.quick ? " --quick" : ""),
                    case_count(plan), "cases");
  long long done = 0;
  const auto tick = [&] { progress.update(++done); };
  for (const Method& m : plan.methods) results.push_back(run_method(plan, m, tick));
  progress.finish();
  return results;
}

// Runs the mass ratio scorecard of the plan's methods, with progress on stderr.
std::vector<ScoreResult> run_score(const PushPlan& plan) {
  const std::vector<ScoreRow> rows = score_rows(plan.methods);
  Progress progress("report push: mass ratio scorecard",
                    static_cast<long long>(rows.size() * kScoreCases.size()) * kScoreRatioPowers, "runs");
  long long done = 0;
  std::vector<ScoreResult> score = run_scorecard(rows, [&] { progress.update(++done); });
  progress.finish();
  return score;
}

}  // namespace

std::vector<std::string> push_report_files() {
  return {"push.csv", "push.md", "push_overlap.png", "push_overlap.pdf", "push_speed.png",
          "push_speed.pdf", "score.csv"};
}

std::vector<std::string> push_plot_files() {
  return {"push_overlap.dat", "push_overlap.gp", "push_speed.dat", "push_speed.gp"};
}

CsvTable push_table(const PushPlan& plan, const std::vector<MethodResults>& results) {
  CsvTable table;
  table.columns = kColumns;
  for (const MethodResults& r : results) {
    for (PushRow& row : rows_of(plan, r)) table.rows.push_back(std::move(row.cells));
  }
  return table;
}

int run_push_report(const fs::path& out, bool quick, bool force, const nlohmann::json& info) {
  // Every target checked before any work.
  const OutputPlan main = plan_output({.folder = out,
                                       .files = push_report_files(),
                                       .command = "report",
                                       .use = FolderUse::shared,
                                       .scenes = {},
                                       .force = force});
  const OutputPlan plots = plan_output({.folder = out / "plots",
                                        .files = push_plot_files(),
                                        .command = "report",
                                        .use = FolderUse::shared,
                                        .scenes = {},
                                        .force = force});
  const PushPlan plan = plan_push_report(quick);
  const auto started = std::chrono::steady_clock::now();
  const std::vector<MethodResults> results = run_methods(plan);
  const std::vector<ScoreResult> score = run_score(plan);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const CsvTable csv = push_table(plan, results);
  const SeriesData data = series_data(plan, results);

  begin_output(main, info);
  begin_output(plots, info);
  write_csv(out / "push.csv", csv);
  write_csv(out / "score.csv", score_table(score));
  write_text_atomic(out / "push.md",
                    push_markdown(plan, csv, results, elapsed) + "\n" + score_markdown(score, plan.methods));
  write_diagram(out, "push_overlap", data.text,
                diagram_script(out / "plots" / "push_overlap.dat", plan.methods, 1,
                               "largest overlap against time (values under " +
                                   number(kOverlapFloor) + " m drawn on the bottom edge)",
                               "largest overlap (m)", kOverlapFloor, data.overlap_max, data.t_max, true));
  write_diagram(out, "push_speed", data.text,
                diagram_script(out / "plots" / "push_speed.dat", plan.methods, 2,
                               "largest body speed against time (values under " +
                                   number(kSpeedFloor) + " m/s drawn on the bottom edge)",
                               "largest body speed (m/s)", kSpeedFloor, data.speed_max, data.t_max, false));
  end_output(plots, info);
  end_output(main, info);
  std::printf("%zu push methods in %.0f s: %s\n", plan.methods.size(), elapsed,
              (out / "push.md").string().c_str());
  return 0;
}

}  // namespace cps::cli
