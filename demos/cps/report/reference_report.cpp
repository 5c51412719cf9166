#include "report/reference_report.h"

#include "report/csv.h"
#include "report/gnuplot.h"
#include "report/plan.h"
#include "report/references.h"
#include "report/run.h"
#include "report/studies.h"
#include "output/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// Values under these are drawn on them (log axes): relative error and velocity error of the
// solver-error diagram (dimensionless, m/s), the references' distance (m), the constraint error
// of the energy diagram (m).
constexpr double kSolverErrorFloor = 1e-16;
constexpr double kDistanceFloor = 1e-12;
constexpr double kConstraintFloor = 1e-9;

const char* const kPgsColours[] = {"#9ecae1", "#4292c6", "#08519c", "#08306b"};
const char* const kJacobiColours[] = {"#fcae91", "#fb6a4a", "#cb181d", "#67000d"};
const char* const kPushColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

// A value for a gnuplot data file: NaN (skipped) when not finite, else at least `floor`.
std::string dat(double v, double floor) {
  if (!std::isfinite(v)) return "NaN";
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", std::max(v, floor));
  return text;
}

// The gnuplot head of a picture of panels side by side with a title and a key row under them
// (key_h: the key's height, a fraction of the picture).
std::string multiplot_head(const std::string& title, double key_h) {
  return "set multiplot\nset label 100 " + gp_text(title) +
         " at screen 0.5, screen 0.97 center font ',12'\nset grid lc rgb '#d8d8d8'\n"
         "set tics font ',8'\nunset key\nset lmargin 10\nset rmargin 2\nset tmargin 2.5\n"
         "set bmargin 3\nset xlabel 'simulated time (s)' font ',9'\n" +
         std::string("set size 0.5, ") + std::to_string(0.95 - key_h) + "\n";
}

// The key row: a frameless plot of nothing with `entries` ("style title 'x'" each).
std::string key_row(const std::vector<std::string>& entries, double key_h, int rows) {
  std::ostringstream gp;
  gp << "unset label\nunset arrow\nunset xlabel\nunset ylabel\nunset logscale\nunset border\n"
        "unset tics\nunset grid\nset origin 0, 0\nset size 1, "
     << key_h << "\nset lmargin 0\nset rmargin 0\nset tmargin 0\nset bmargin 0\n"
     << "set xrange [0:1]\nset yrange [0:1]\nset key center center horizontal maxrows " << rows
     << " width 1 samplen 3 font ',9'\nplot ";
  for (std::size_t i = 0; i < entries.size(); ++i) gp << (i ? ", " : "") << "NaN " << entries[i];
  gp << "\nunset multiplot\n";
  return gp.str();
}

// --- Solver error -------------------------------------------------------------------------

struct Line {
  std::string method;
  int sweeps = 0;
};

std::vector<Line> solver_lines() {
  std::vector<Line> lines;
  for (const char* m : {"pgs", "jacobi"}) {
    for (const int k : kSolverErrorSweepCounts) lines.push_back({m, k});
  }
  return lines;
}

std::string line_style(const Line& l) {
  std::size_t i = 0;
  while (kSolverErrorSweepCounts[i] != l.sweeps) ++i;
  return l.method == "pgs"
             ? std::string("with linespoints lw 1.5 pt 7 ps 0.5 lc rgb '") + kPgsColours[i] + "'"
             : std::string("with linespoints lw 1.5 dt 2 pt 4 ps 0.5 lc rgb '") + kJacobiColours[i] + "'";
}

// Median of the finite values (NaN if none).
double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double largest(const std::vector<double>& v) {
  double m = std::nan("");
  for (const double x : v) {
    if (std::isfinite(x) && !(x <= m)) m = x;
  }
  return m;
}

std::string solver_error_section(const fs::path& dir, const std::string& scene,
                                 const SceneStudies& studies, const std::string& title_note) {
  const std::string stem = file_stem(scene) + "_solver_error";
  const int samples = studies.samples;
  const int no_solve = studies.no_solve;
  const std::vector<SolverErrorPoint>& points = studies.solver_error;

  write_csv(dir / (stem + ".csv"), solver_error_table(scene, studies));

  // Per line: times, relative errors, velocity errors; counts of diverged sweeps (non-finite).
  const std::vector<Line> lines = solver_lines();
  std::ostringstream data;
  std::vector<std::vector<double>> rel(lines.size()), vel(lines.size());
  std::vector<int> overflowed(lines.size(), 0);
  double exact_residual = 0.0;
  std::vector<const SolverErrorPoint*> refused;
  std::size_t solves = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    for (const SolverErrorPoint& p : points) {
      if (p.method != lines[i].method || p.sweeps != lines[i].sweeps) continue;
      data << p.t_s << " " << dat(p.relative, kSolverErrorFloor) << " "
           << dat(p.velocity_mps, kSolverErrorFloor) << "\n";
      rel[i].push_back(p.relative);
      vel[i].push_back(p.velocity_mps);
      if (!std::isfinite(p.relative) || !std::isfinite(p.velocity_mps)) ++overflowed[i];
    }
    data << "NaN NaN NaN\n\n\n";
  }
  for (const SolverErrorPoint& p : points) {
    if (p.method != "exact") continue;
    ++solves;
    if (!p.refused.empty()) refused.push_back(&p);
    else exact_residual = std::max(exact_residual, p.residual_N);
  }
  const fs::path dat_file = dir / "plots" / (stem + ".dat");
  write_text_atomic(dat_file, data.str());

  const double key_h = 0.12;
  std::ostringstream gp;
  gp << multiplot_head(scene + ": solver error per step against the exact solution, paper's "
                       "settings (PGS and Jacobi from 0 on the same systems)" + title_note, key_h)
     << "set logscale y\nset format y '1e%T'\n";
  for (int panel = 0; panel < 2; ++panel) {
    gp << "set origin " << 0.5 * panel << ", " << key_h << "\n"
       << "set ylabel " << gp_text(panel == 0 ? "force error |lambda - lambda*| / |lambda*|"
                                               : "velocity error dt |A (lambda - lambda*)| (m/s)")
       << " font ',9'\nplot ";
    for (std::size_t i = 0; i < lines.size(); ++i) {
      gp << (i ? ", \\\n     " : "") << (i ? std::string("''") : gp_text(dat_file.string()))
         << " index " << i << " using 1:" << 2 + panel << " " << line_style(lines[i]);
    }
    gp << "\n";
    if (panel == 0) gp << "unset label 100\n";
  }
  std::vector<std::string> entries;
  for (const Line& l : lines) {
    entries.push_back(line_style(l) + " title " +
                      gp_text(l.method + " " + std::to_string(l.sweeps) + " sweeps"));
  }
  gp << key_row(entries, key_h, 2);
  draw_png_svg_pdf(dir, stem, "reset\n" + gp.str(), 1100, 520);

  std::ostringstream md;
  md << "### Solver error per step\n\n"
     << "The run at the paper's settings (PGS, " << kPaperIterations
     << " iterations, Baumgarte push, fixed friction, 1 substep), " << samples
     << " steps sampled evenly to the horizon: each solve of a sampled step is solved exactly "
        "(Siconos' Lemke method, polished: docs/exact_reference.md), and the engine's PGS and "
        "Jacobi sweeps, from lambda = 0 on the same system, are judged against it: the force "
        "error, the distance to the set of exact solutions (certified by a dual bound, or else to "
        "the nearest member found: docs/exact_reference.md), over |lambda*| (the least-norm exact "
        "solution), and the velocity error it "
        "leaves, dt |A (lambda - lambda*)| (m/s). This is the solver's error alone, step by "
        "step; the trajectory error below mixes it with the time step's. "
     << solves << " solves" << (no_solve ? ", " + std::to_string(no_solve) +
                                    " sampled steps without a solve (no contact or rod)" : "")
     << "; the exact solutions' largest natural-map residual " << number(exact_residual)
     << " N. Data: [" << stem << ".csv](" << stem << ".csv).\n\n";
  if (!refused.empty()) {
    md << "**The exact solve refused " << refused.size() << " of the " << solves
       << " solves** (no error drawn there):";
    for (std::size_t i = 0; i < refused.size() && i < 10; ++i) {
      md << (i ? ";" : "") << " step " << refused[i]->step << " (t = " << number(refused[i]->t_s)
         << " s, " << refused[i]->rows << " rows): " << refused[i]->refused;
    }
    if (refused.size() > 10) md << "; and " << refused.size() - 10 << " more (the CSV)";
    md << ".\n\n";
  }
  md << "| method | sweeps | median relative force error | largest | median velocity error "
        "(m/s) | largest | diverged |\n|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    md << "| " << lines[i].method << " | " << lines[i].sweeps << " | " << number(median(rel[i]))
       << " | " << number(largest(rel[i])) << " | " << number(median(vel[i])) << " | "
       << number(largest(vel[i])) << " | " << overflowed[i] << " |\n";
  }
  md << "\n![" << scene << " solver error](" << stem << ".png)\n\n";
  return md.str();
}

// --- The two references --------------------------------------------------------------------

std::string references_section(const fs::path& dir, const std::string& scene,
                               const SceneStudies& studies, const std::string& title_note) {
  const scenes::Scene* s = scenes::find_scene(scene);
  if (s == nullptr || !studies.agreement) return "";
  const ReferenceAgreement* a = &*studies.agreement;
  const std::string stem = file_stem(scene) + "_references";
  std::ostringstream data;
  for (std::size_t i = 0; i < a->t_s.size(); ++i) {
    data << a->t_s[i] << " " << dat(a->distance_m[i], kDistanceFloor) << "\n";
  }
  write_csv(dir / (stem + ".csv"), references_table(scene, studies));
  const fs::path dat_file = dir / "plots" / (stem + ".dat");
  write_text_atomic(dat_file, data.str() + "NaN NaN\n");

  const double t_scene = std::min(s->report_trajectory_time_s(), s->report_horizon_s());
  const double t_used = trajectory_time_with(*s, a);
  double top = a->tolerance_m;
  for (const double d : a->distance_m) top = std::max(top, std::isfinite(d) ? d : top);
  std::ostringstream gp;
  gp << "set yrange [" << 0.5 * kDistanceFloor << ":" << 10.0 * top << "]\nset xrange [0:"
     << 1.05 * std::max(t_used, a->checked_until_s) << "]\n";
  gp << "set title " << gp_text(scene + ": distance between the two references (PGS " +
                                std::to_string(kReferenceIterations) + " sweeps and the exact "
                                "solve, both " + std::to_string(reference_substeps(studies.quick)) +
                                " substeps)" + title_note)
     << " font ',11'\nset logscale y\nset format y '1e%T'\nset grid lc rgb '#d8d8d8'\n"
     << "set xlabel 'simulated time (s)'\nset ylabel 'RMS distance of the bodies (m)'\n"
     << "set key top left font ',9'\n"
     << "set arrow 1 from graph 0, first " << a->tolerance_m << " to graph 1, first "
     << a->tolerance_m << " nohead dt 3 lw 1.2 lc rgb 'gray30'\n"
     << "set arrow 2 from first " << t_used << ", graph 0 to first " << t_used
     << ", graph 1 nohead dt 4 lw 1.2 lc rgb '#b8860b'\n"
     << "plot " << gp_text(dat_file.string())
     << " using 1:2 with linespoints lw 1.5 pt 7 ps 0.5 lc rgb '#1f77b4' title 'distance', "
     << "NaN with lines dt 3 lw 1.2 lc rgb 'gray30' title "
     << gp_text("tolerance " + number(a->tolerance_m) + " m") << ", "
     << "NaN with lines dt 4 lw 1.2 lc rgb '#b8860b' title "
     << gp_text("trajectory time used, " + number(t_used) + " s") << "\n";
  draw_png_svg_pdf(dir, stem, "reset\n" + gp.str(), 900, 420);

  std::ostringstream md;
  md << "### Two references and the horizon\n\n"
     << "Two independent references at the same small dt (" << reference_substeps(studies.quick)
     << " substeps per 1/60 s frame, Baumgarte push, fixed friction, cold): PGS at "
     << kReferenceIterations << " sweeps a solve (the trajectory error's reference), and the "
        "exact solve of every step's system in place of the sweeps (World::set_solve_override). "
        "Where they agree, the reference's solver error is below the stated distance and the "
        "trajectory error measures the method and its time step; where they part, the "
        "trajectory is decided by the solver's leftovers (chaos), and only invariants and "
        "residuals (penetration, rod error, energy drift: the run table's columns and the "
        "energy diagram below) mean anything. Distance: the RMS distance of the movable "
        "bodies; tolerance " << number(a->tolerance_m) << " m (" << number(100 * kAgreementFraction)
     << " % of the largest movable body).\n\n- **Horizon**: ";
  if (std::isinf(a->horizon_s)) {
    md << "none found: within the tolerance at every step to " << number(a->checked_until_s)
       << " s";
  } else {
    md << "**" << number(a->horizon_s) << " s**, the last step before they part by more than "
       << "the tolerance";
  }
  md << " (checked to " << number(a->checked_until_s) << " s"
     << (a->stopped.empty() ? std::string(", the trajectory time") : "; stopped by " + a->stopped)
     << "; " << a->exact_solves << " exact solves, " << number(a->exact_cpu_s)
     << " s of CPU).\n- **Trajectory time**: the scene's " << number(t_scene) << " s; ";
  if (t_used < t_scene) {
    md << "it is past the horizon, so the trajectory error is measured at " << number(t_used)
       << " s (the horizon rounded down to a whole 1/60 s frame).";
  } else if (!a->stopped.empty()) {
    md << "measured there; the agreement was checked only to " << number(a->checked_until_s)
       << " s, so beyond that the trajectory error is not backed by the exact reference.";
  } else {
    md << "inside the horizon, measured there.";
  }
  md << "\n\n![" << scene << " references](" << stem << ".png)\n\n";
  return md.str();
}

// --- Energy over time ------------------------------------------------------------------------

std::string energy_section(const fs::path& dir, const std::string& scene,
                           const SceneStudies& studies, const std::string& title_note) {
  const std::string stem = file_stem(scene) + "_energy";
  const std::vector<EnergyTrace>& traces = studies.energy;
  if (traces.empty()) return "";
  std::ostringstream data;
  for (const EnergyTrace& e : traces) {
    for (std::size_t i = 0; i < e.t_s.size(); ++i) {
      data << e.t_s[i] << " " << dat(e.total_J[i], -1e300) << " "
           << dat(std::max(e.penetration_m[i], e.rod_error_m[i]), kConstraintFloor) << "\n";
    }
    data << "NaN NaN NaN\n\n\n";
  }
  write_csv(dir / (stem + ".csv"), energy_table(scene, studies));
  const fs::path dat_file = dir / "plots" / (stem + ".dat");
  write_text_atomic(dat_file, data.str());

  const auto style = [](std::size_t i) {
    return std::string("with lines lw 1.5 lc rgb '") +
           kPushColours[i % (sizeof kPushColours / sizeof kPushColours[0])] + "'";
  };
  const double key_h = 0.08;
  std::ostringstream gp;
  gp << multiplot_head(scene + ": energy and constraint error over time, each push method at "
                       "the paper's settings otherwise (PGS, 25 iterations, 60 Hz)" + title_note,
                       key_h);
  for (int panel = 0; panel < 2; ++panel) {
    gp << "set origin " << 0.5 * panel << ", " << key_h << "\n";
    if (panel == 0) {
      gp << "set ylabel 'total mechanical energy KE + PE (J)' font ',9'\n";
    } else {
      gp << "set logscale y\nset format y '1e%T'\nset ylabel 'constraint error: deepest contact "
            "or largest rod error (m)' font ',9'\n";
    }
    gp << "plot ";
    for (std::size_t i = 0; i < traces.size(); ++i) {
      gp << (i ? ", \\\n     " : "") << (i ? std::string("''") : gp_text(dat_file.string()))
         << " index " << i << " using 1:" << 2 + panel << " " << style(i);
    }
    gp << "\n";
    if (panel == 0) gp << "unset label 100\n";
  }
  std::vector<std::string> entries;
  for (std::size_t i = 0; i < traces.size(); ++i) {
    entries.push_back(style(i) + " title " + gp_text(traces[i].push));
  }
  gp << key_row(entries, key_h, 1);
  draw_png_svg_pdf(dir, stem, "reset\n" + gp.str(), 1100, 480);

  std::ostringstream md;
  md << "### Energy over time\n\n"
     << "Each push method at the paper's settings otherwise (PGS, " << kPaperIterations
     << " iterations, 1 substep, fixed friction, cold), to the horizon: the mechanical energy "
        "KE + PE of the movable bodies (J; PE from the datum y = 0) and the constraint error (the "
        "deepest contact or the largest rod length error, m, whichever is larger; drawn at "
     << number(kConstraintFloor) << " m when below). A rise of the energy is energy the method "
        "injected (the Baumgarte push turns overlap into velocity); a fall is dissipation "
        "(friction, inelastic contact, PGS stopped early). Data: [" << stem << ".csv](" << stem
     << ".csv).\n\n| push | E at 0 (J) | E at the end (J) | largest rise above E(0) (J) | "
        "largest constraint error (m) | diverged at (s) |\n|---|---|---|---|---|---|\n";
  for (const EnergyTrace& e : traces) {
    double rise = 0.0;
    double constraint = 0.0;
    for (std::size_t i = 0; i < e.t_s.size(); ++i) {
      if (std::isfinite(e.total_J[i])) rise = std::max(rise, e.total_J[i] - e.total_J.front());
      constraint = std::max({constraint, e.penetration_m[i], e.rod_error_m[i]});
    }
    md << "| " << e.push << " | " << number(e.total_J.front()) << " | "
       << number(e.total_J.back()) << " | " << number(rise) << " | " << number(constraint)
       << " | " << (std::isnan(e.diverged_at_s) ? std::string("-") : number(e.diverged_at_s))
       << " |\n";
  }
  md << "\n![" << scene << " energy](" << stem << ".png)\n\n";
  return md.str();
}

}  // namespace

bool has_reference_sections(const std::string& scene) {
  for (const scenes::Scene& s : scenes::paper_scenes()) {
    if (s.name == scene) return true;
  }
  return false;
}

std::map<std::string, std::map<int, double>> solver_error_medians(const SceneStudies& studies) {
  std::map<std::string, std::map<int, std::vector<double>>> values;
  for (const SolverErrorPoint& p : studies.solver_error) {
    if (p.method == "exact" || std::isnan(p.relative)) continue;
    values[p.method][p.sweeps].push_back(p.relative);
  }
  std::map<std::string, std::map<int, double>> out;
  for (auto& [method, by_sweeps] : values) {
    for (auto& [sweeps, v] : by_sweeps) {
      std::sort(v.begin(), v.end());
      const std::size_t n = v.size();
      out[method][sweeps] = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
  }
  return out;
}

std::string write_reference_sections(const fs::path& dir, const std::string& scene,
                                     const SceneStudies& studies, const std::string& title_note) {
  if (!has_reference_sections(scene)) return "";
  return (studies.samples > 0 ? solver_error_section(dir, scene, studies, title_note) : "") +
         references_section(dir, scene, studies, title_note) +
         energy_section(dir, scene, studies, title_note);
}

std::vector<std::string> reference_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files;
  for (const std::string& scene : scenes) {
    if (!has_reference_sections(scene)) continue;
    for (const char* part : kReferenceParts) {
      for (const char* ext : {".csv", ".png", ".svg", ".pdf"}) {
        files.push_back(file_stem(scene) + "_" + part + ext);
      }
    }
  }
  return files;
}

std::vector<std::string> reference_plot_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files;
  for (const std::string& scene : scenes) {
    if (!has_reference_sections(scene)) continue;
    for (const char* part : kReferenceParts) {
      for (const char* ext : {".dat", ".gp"}) files.push_back(file_stem(scene) + "_" + part + ext);
    }
  }
  return files;
}

}  // namespace cps::cli
