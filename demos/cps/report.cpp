#include "report.h"

#include "command.h"
#include "options.h"
#include "output.h"
#include "progress.h"
#include "stress/mass_ratio.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// The trajectory error compares positions with a reference run (16 substeps, 256 iterations) at
// this time (s). Contacts make these scenes chaotic: once a stack starts to slide or balls start
// to roll past each other, nearby trajectories part exponentially and a difference measures
// chaos, not accuracy. Before the first impacts have settled they do not: 1 s covers the first
// falls, landings and catches of the paper's scenes; a scene whose report horizon is shorter
// (Scene::report) is compared at its horizon.
double trajectory_time_of(const scenes::Scene& scene) {
  return std::min(1.0, scene.report_horizon_s());
}

std::string name(SolverKind v) { return std::string(name_of(v)); }
std::string name(PushMode v) { return std::string(name_of(v)); }
std::string name(FrictionModel v) { return std::string(name_of(v)); }

// The value of a choice parameter called `text` in a run id, or std::nullopt.
template <class Enum>
std::optional<Enum> choice_of(const char* parameter_name, const std::string& text) {
  const Choice* c = parameter(parameter_name).find_choice(text);
  if (c == nullptr) return std::nullopt;
  return static_cast<Enum>(c->value);
}

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

bool has_friction(const scenes::Scene& scene) { return scene.world_def().friction > 0.0; }

// True if `scene` is one of the paper's scenes (its table, scenes::paper_scenes()).
bool is_paper_scene(const scenes::Scene& scene) {
  for (const scenes::Scene& s : scenes::paper_scenes()) {
    if (s.name == scene.name) return true;
  }
  return false;
}

// The full size (m) of the largest movable body: a box's longest edge, a ball's diameter.
double largest_body_size(const World& world) {
  double size = 0.0;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    size = std::max(size, b.shape.kind == ShapeKind::sphere ? 2.0 * b.shape.radius
                                                            : 2.0 * b.shape.half_extents.maxCoeff());
  }
  return size > 0.0 ? size : kInfinity;
}

const scenes::Scene& scene_of(const RunSpec& spec) {
  const scenes::Scene* scene = scenes::find_scene(spec.scene);
  if (!scene) throw UsageError("report: unknown scene '" + spec.scene + "'");
  return *scene;
}

// The most substeps a run may take per frame (count): dt = 1 / (60 x 1000) s at the most.
constexpr int kMaxSubsteps = 1000;

// dt is 1 / (60 substeps) for the paper's scenes (substeps of the paper's 60 Hz frame), and the
// scene's own dt / substeps for the others (stress scenes choose their dt on purpose).
scenes::Overrides overrides_of(const RunSpec& spec) {
  const scenes::Scene& scene = scene_of(spec);
  scenes::Overrides o;
  o.set("solver", spec.solver);
  o.set("push", spec.push);
  o.set("friction_model", spec.friction_model);
  o.set("iterations", spec.iterations);
  o.set("dt", is_paper_scene(scene) ? 1.0 / (60.0 * spec.substeps)
                                    : scene.world_def().dt / spec.substeps);
  return o;
}

std::vector<Vec3> positions(const World& world) {
  std::vector<Vec3> x;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) x.push_back(b.x);
  }
  return x;
}

// False once the state is not finite, or a body is further than 1e6 m away or faster than
// 1e6 m/s: the run has blown up and goes no further.
bool sane_state(const World& world) {
  for (const Body& b : world.bodies()) {
    if (!b.x.allFinite() || !b.p.allFinite() || !b.l.allFinite() || !b.o.coeffs().allFinite()) {
      return false;
    }
    if (b.x.norm() > 1e6 || b.velocity().norm() > 1e6) return false;
  }
  return true;
}

// Positions of the reference run (pgs, 256 iterations, 16 substeps, same push and friction
// model) at the trajectory time; computed once per process and kept.
std::vector<Vec3> reference_positions(const RunSpec& spec) {
  static std::mutex mutex;
  static std::map<std::string, std::vector<Vec3>> cache;
  RunSpec ref = spec;
  ref.solver = SolverKind::pgs;
  ref.iterations = 256;
  ref.substeps = 16;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto it = cache.find(ref.id());
  if (it != cache.end()) return it->second;
  const scenes::Scene& scene = scene_of(ref);
  scenes::Run run = scenes::make_run(scene, overrides_of(ref));
  run.world.step();  // at least one step, as every run below
  while (run.world.time() + 0.5 * run.world.def().dt < trajectory_time_of(scene)) run.world.step();
  return cache[ref.id()] = positions(run.world);
}

// The numeric entries of a scene's metrics, as "metric.NAME" columns (booleans as 0/1, arrays
// and nulls left out).
void add_metrics(const nlohmann::json& metrics, Row& row) {
  for (const auto& [key, value] : metrics.items()) {
    if (value.is_number()) row["metric." + key] = number(value.get<double>());
    if (value.is_boolean()) row["metric." + key] = value.get<bool>() ? "1" : "0";
  }
}

double to_double(const Row& row, const std::string& column) {
  const auto it = row.find(column);
  if (it == row.end() || it->second.empty()) return std::nan("");
  return std::strtod(it->second.c_str(), nullptr);
}

// Columns in the order a reader wants them: the settings, then the measures, then metrics.
std::vector<std::string> ordered_columns(const std::vector<Row>& rows) {
  static const std::vector<std::string> first = {
      "scene", "solver", "push", "friction_model", "iterations", "substeps", "dt_s", "horizon_s",
      "diverged", "wall_s_per_sim_s", "us_per_step", "trajectory_time_s", "trajectory_error_m",
      "phase_error_deg", "residual_max_N", "residual_rms_N", "penetration_max_m",
      "penetration_rms_m", "rod_error_max_m", "rod_error_rms_m", "energy_drift_rel"};
  std::set<std::string> all;
  for (const Row& r : rows) {
    for (const auto& kv : r) all.insert(kv.first);
  }
  std::vector<std::string> columns;
  for (const std::string& c : first) {
    if (all.erase(c)) columns.push_back(c);
  }
  columns.insert(columns.end(), all.begin(), all.end());
  return columns;
}

// What the work-precision diagrams show, with axis labels.
struct Measure {
  const char* column;
  const char* label;
};
constexpr Measure kMeasures[] = {
    {"trajectory_error_m", "trajectory error against the reference run (m)"},
    {"phase_error_deg", "largest phase error against the reduced-coordinate reference (deg)"},
    {"residual_rms_N", "RMS LCP residual (N)"},
    {"penetration_max_m", "largest penetration (m)"},
    {"rod_error_max_m", "largest rod length error (m)"},
    {"energy_drift_rel", "largest relative energy drift"},
    {"metric.max_speed_mps", "largest body speed at the end (m/s)"},
};

// The error measure the headline of the scene called `scene` uses (its Scene::report); the
// default one for a name no scene has (a CSV of an older build).
std::string primary_measure(const std::string& scene) {
  const scenes::Scene* s = scenes::find_scene(scene);
  return std::string(s ? s->report.primary_measure : scenes::ReportTraits{}.primary_measure);
}

std::string variant_of(const Row& r) {
  return r.at("solver") + " " + r.at("push") + " " + r.at("friction_model");
}

bool is_paper_setting(const Row& r) {
  return r.at("solver") == "pgs" && r.at("push") == "baumgarte" &&
         r.at("friction_model") == "fixed" && r.at("iterations") == "25" && r.at("substeps") == "1";
}

void run_gnuplot(const fs::path& script) {
  const std::string command = "gnuplot '" + script.string() + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("report: cannot start gnuplot");
  std::string output;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  if (status != 0) {
    throw std::runtime_error(
        "report: gnuplot failed on " + script.string() + " (exit " + std::to_string(status) +
        "): " + output.substr(0, 400) +
        (status == 127 * 256 ? "\nInstall it with: apt-get install gnuplot-nox" : ""));
  }
}

// One diagram: error against physics time, log-log, a line per variant and sweep, points
// labelled by iterations (solid lines) or substeps (dashed).
bool plot_measure(const fs::path& dir, const std::string& scene, const Measure& m,
                  const std::vector<const Row*>& rows) {
  struct Line {
    std::string title;
    bool substeps;
    std::vector<std::tuple<double, double, std::string>> points;
  };
  std::map<std::string, Line> lines;
  for (const Row* r : rows) {
    const double t = to_double(*r, "wall_s_per_sim_s");
    const double e = to_double(*r, m.column);
    if (!(t > 0.0) || !(e > 0.0)) continue;  // log axes: only positive values
    const bool iteration_sweep = r->at("substeps") == "1";
    const bool substep_sweep = r->at("iterations") == "25";
    if (iteration_sweep) {
      Line& line = lines[variant_of(*r) + ", iterations"];
      line.title = variant_of(*r) + ", iterations";
      line.points.emplace_back(t, e, r->at("iterations"));
    }
    if (substep_sweep) {
      Line& line = lines[variant_of(*r) + ", substeps"];
      line.title = variant_of(*r) + ", substeps";
      line.substeps = true;
      line.points.emplace_back(t, e, "s" + r->at("substeps"));
    }
  }
  if (lines.empty()) return false;
  // Runs that blow up (Jacobi on contact stacks) would squash every other line into the bottom
  // of the diagram: the y range stops a decade above the largest PGS value; the table and the
  // CSV keep every figure.
  double pgs_max = 0.0;
  for (const Row* r : rows) {
    if (r->at("solver") == "pgs") pgs_max = std::max(pgs_max, to_double(*r, m.column));
  }
  const std::string stem = scene + "_" + m.column;
  const fs::path data = dir / "plots" / (stem + ".dat");
  const fs::path script = dir / "plots" / (stem + ".gp");
  fs::create_directories(dir / "plots");
  {
    std::ofstream out(data);
    for (auto& [key, line] : lines) {
      std::sort(line.points.begin(), line.points.end());
      out << "# " << line.title << "\n";
      for (const auto& [t, e, label] : line.points) out << t << " " << e << " " << label << "\n";
      out << "\n\n";
    }
  }
  std::ofstream gp(script);
  gp << "set logscale xy\nset grid\nset key outside right top font ',9'\n"
     << "set xlabel 'physics wall time per simulated second (s/s)'\n"
     << "set ylabel '" << m.label << "'\n"
     << "set title '" << scene << ": " << m.label << " against run time'\n";
  if (pgs_max > 0.0) gp << "set yrange [*:" << 10.0 * pgs_max << "]\n";
  // One colour per variant (solver, push, friction model); iterations solid, substeps dashed.
  std::map<std::string, int> colour;
  for (const auto& [key, line] : lines) {
    const std::string variant = key.substr(0, key.rfind(','));
    colour.emplace(variant, static_cast<int>(colour.size()) + 1);
  }
  std::string plot = "plot ";
  int index = 0;
  for (const auto& [key, line] : lines) {
    const int lc = colour.at(key.substr(0, key.rfind(',')));
    plot += (index ? ", " : "") + std::string("'") + data.string() + "' index " +
            std::to_string(index) + " using 1:2 with linespoints lw 1.5 pt 7 ps 0.6 dt " +
            (line.substeps ? "2" : "1") + " lc " + std::to_string(lc) + " title '" +
            line.title + "', '' index " + std::to_string(index) +
            " using 1:2:3 with labels offset 0.6,0.6 font ',7' tc lt " + std::to_string(lc) +
            " notitle";
    ++index;
  }
  gp << "set terminal pngcairo size 1100,650 font ',10' noenhanced\nset output '"
     << (dir / (stem + ".png")).string() << "'\n" << plot << "\n";
  gp << "set terminal svg size 1100,650 font ',10' noenhanced\nset output '"
     << (dir / (stem + ".svg")).string() << "'\n" << plot << "\nunset output\n";
  gp.close();
  run_gnuplot(script);
  return true;
}

}  // namespace

std::string RunSpec::id() const {
  return scene + "." + name(solver) + "." + name(push) + "." + name(friction_model) +
         ".it" + std::to_string(iterations) + ".ss" + std::to_string(substeps);
}

RunSpec RunSpec::parse(const std::string& id) {
  // The last five parts are the settings; the scene is what comes before them (scene names may
  // hold a dot: pendulum_wave_dt_0.1).
  std::vector<std::string> parts;
  std::stringstream s(id);
  for (std::string part; std::getline(s, part, '.');) parts.push_back(part);
  const auto bad = [&id](const std::string& why) {
    return UsageError("run id '" + id + "': " + why +
                      "; expected scene.pgs|jacobi.baumgarte|split.fixed|coupled.itN.ssM");
  };
  if (parts.size() < 6) throw bad("it has " + std::to_string(parts.size()) + " parts, not 6");
  while (parts.size() > 6) {
    parts[0] += "." + parts[1];
    parts.erase(parts.begin() + 1);
  }
  RunSpec r;
  r.scene = parts[0];
  if (!scenes::find_scene(r.scene)) throw bad("unknown scene");
  const auto solver = choice_of<SolverKind>("solver", parts[1]);
  if (!solver) throw bad("unknown solver '" + parts[1] + "'");
  const auto push = choice_of<PushMode>("push", parts[2]);
  if (!push) throw bad("unknown push '" + parts[2] + "'");
  const auto friction_model = choice_of<FrictionModel>("friction_model", parts[3]);
  if (!friction_model) throw bad("unknown friction model '" + parts[3] + "'");
  r.solver = *solver;
  r.push = *push;
  r.friction_model = *friction_model;
  // A whole decimal count after the prefix, nothing else ("it4294967297" and "it1x" are refused).
  const auto count = [&](const std::string& p, const char* prefix, int most) {
    if (p.rfind(prefix, 0) != 0) throw bad("'" + p + "' does not start with " + prefix);
    int n = 0;
    const char* first = p.c_str() + 2;
    const char* last = p.c_str() + p.size();
    const auto [end, ec] = std::from_chars(first, last, n);
    if (first == last || ec != std::errc() || end != last || n < 1 || n > most) {
      throw bad("'" + p + "' is not a count in [1, " + std::to_string(most) + "]");
    }
    return n;
  };
  r.iterations = count(parts[4], "it", static_cast<int>(parameter("iterations").max));
  r.substeps = count(parts[5], "ss", kMaxSubsteps);
  const scenes::Scene& scene = scene_of(r);
  check_steps("run " + id, scene.report_horizon_s(), std::get<double>(*overrides_of(r).find("dt")));
  return r;
}

std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick) {
  const std::vector<int> iterations =
      quick ? std::vector<int>{1, 4, 16, 25, 64} : std::vector<int>{1, 2, 4, 8, 16, 25, 32, 64, 128, 256};
  const std::vector<int> substeps = quick ? std::vector<int>{4} : std::vector<int>{2, 4, 8, 16};
  std::vector<RunSpec> runs;
  for (const scenes::Scene* scene : scenes) {
    std::vector<FrictionModel> frictions = {FrictionModel::fixed};
    if (!quick && has_friction(*scene)) frictions.push_back(FrictionModel::coupled);
    for (const FrictionModel f : frictions) {
      for (const PushMode p : {PushMode::baumgarte, PushMode::split}) {
        for (const SolverKind s : {SolverKind::pgs, SolverKind::jacobi}) {
          for (const int it : iterations) runs.push_back({std::string(scene->name), s, p, f, it, 1});
          for (const int ss : substeps) runs.push_back({std::string(scene->name), s, p, f, 25, ss});
        }
      }
    }
  }
  return runs;
}

Row execute_run(const RunSpec& spec, int repeats) {
  const scenes::Scene& scene = scene_of(spec);
  const double horizon = scene.report_horizon_s();
  const double t_traj = trajectory_time_of(scene);
  scenes::Overrides o = overrides_of(spec);
  Row row;
  row["scene"] = spec.scene;
  // The columns of the settings are the table's JSON keys.
  row[std::string(parameter("solver").json_key)] = name(spec.solver);
  row[std::string(parameter("push").json_key)] = name(spec.push);
  row[std::string(parameter("friction_model").json_key)] = name(spec.friction_model);
  row[std::string(parameter("iterations").json_key)] = std::to_string(spec.iterations);
  row["substeps"] = std::to_string(spec.substeps);
  row[std::string(parameter("dt").json_key)] = number(std::get<double>(*o.find("dt")));
  row["horizon_s"] = number(horizon);

  // The error run: residuals on, every step observed.
  o.set("measure_residual", true);
  const auto error_start = std::chrono::steady_clock::now();
  scenes::Run run = scenes::make_run(scene, o);
  double pen_max = 0.0, pen_sq = 0.0, rod_max = 0.0, rod_sq = 0.0;
  std::int64_t pen_n = 0, rod_n = 0;
  std::vector<Vec3> at_traj;
  bool diverged = false;
  // A run has diverged when its state is not finite or its penetration or rod error passes the
  // size of the largest movable body (bodies then pass through each other, rods stretch past any
  // shape in the scene): its numbers measure the blow-up, not the method's accuracy.
  const double size_bound = largest_body_size(run.world);
  while (run.world.time() + 0.5 * run.world.def().dt < horizon) {
    run.step();
    if (!sane_state(run.world)) {
      diverged = true;
      break;
    }
    for (const Manifold& m : run.world.manifolds()) {
      for (int i = 0; i < m.count; ++i) {
        const double d = std::max(0.0, m.contacts[static_cast<std::size_t>(i)].depth);
        pen_max = std::max(pen_max, d);
        pen_sq += d * d;
        ++pen_n;
      }
    }
    for (const DistanceConstraint& d : run.world.distances()) {
      Vec3 a;
      Vec3 b;
      distance_endpoints(d, run.world.bodies(), a, b);
      const double e = std::abs((b - a).norm() - d.length);
      rod_max = std::max(rod_max, e);
      rod_sq += e * e;
      ++rod_n;
    }
    if (at_traj.empty() && run.world.time() + 0.5 * run.world.def().dt >= t_traj) {
      at_traj = positions(run.world);
    }
    if (pen_max > size_bound || rod_max > size_bound) {
      diverged = true;
      break;
    }
  }
  row["diverged"] = diverged ? "1" : "0";
  const ResidualStats& res = run.world.residual();
  row["residual_max_N"] = number(res.max);
  row["residual_rms_N"] = number(res.rms());
  if (run.world.def().collision) {
    row["penetration_max_m"] = number(pen_max);
    row["penetration_rms_m"] = number(pen_n ? std::sqrt(pen_sq / static_cast<double>(pen_n)) : 0.0);
  }
  if (!run.world.distances().empty()) {
    row["rod_error_max_m"] = number(rod_max);
    row["rod_error_rms_m"] = number(std::sqrt(rod_sq / static_cast<double>(rod_n ? rod_n : 1)));
  }
  if (!diverged) {
    const nlohmann::json metrics = run.metrics->report();
    add_metrics(metrics, row);
    if (metrics.contains("max_phase_error_deg")) {
      row["phase_error_deg"] = number(metrics["max_phase_error_deg"].get<double>());
    }
    if (metrics.contains("energy_drift_rel")) {
      row["energy_drift_rel"] = number(metrics["energy_drift_rel"].get<double>());
    }
    if (!at_traj.empty() && !scene.report.has_reference_solution) {
      const std::vector<Vec3> ref = reference_positions(spec);
      double sq = 0.0;
      for (std::size_t i = 0; i < ref.size() && i < at_traj.size(); ++i) {
        sq += (at_traj[i] - ref[i]).squaredNorm();
      }
      row["trajectory_time_s"] = number(t_traj);
      row["trajectory_error_m"] = number(std::sqrt(sq / static_cast<double>(ref.size())));
    }
  }

  // Timing runs: the physics step alone, residuals off, metrics not fed; the median of repeats.
  // The error run above was the warm-up. A run whose error run took over 2 s is timed once.
  if (std::chrono::duration<double>(std::chrono::steady_clock::now() - error_start).count() > 2.0) {
    repeats = std::min(repeats, 1);
  }
  o.set("measure_residual", false);
  std::vector<double> seconds;
  std::int64_t steps = 0;
  for (int r = 0; r < (diverged ? 0 : repeats); ++r) {
    scenes::Run timed = scenes::make_run(scene, o);
    const auto start = std::chrono::steady_clock::now();
    while (timed.world.time() + 0.5 * timed.world.def().dt < horizon) timed.world.step();
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    steps = timed.world.counters().steps;
  }
  if (!seconds.empty()) {
    std::sort(seconds.begin(), seconds.end());
    const double median = seconds[seconds.size() / 2];
    row["wall_s_per_sim_s"] = number(median / horizon);
    row["us_per_step"] = number(1e6 * median / static_cast<double>(std::max<std::int64_t>(steps, 1)));
  }
  return row;
}

void write_csv(const fs::path& file, const std::vector<Row>& rows) {
  const std::vector<std::string> columns = ordered_columns(rows);
  const fs::path temporary = file.string() + ".tmp";
  {
    std::ofstream out(temporary);
    if (!out) throw std::runtime_error("report: cannot write " + file.string());
    for (std::size_t c = 0; c < columns.size(); ++c) out << (c ? "," : "") << columns[c];
    out << "\n";
    for (const Row& r : rows) {
      for (std::size_t c = 0; c < columns.size(); ++c) {
        const auto it = r.find(columns[c]);
        out << (c ? "," : "") << (it == r.end() ? "" : it->second);
      }
      out << "\n";
    }
  }
  fs::rename(temporary, file);
}

std::vector<Row> read_rows(const std::vector<fs::path>& dirs) {
  std::vector<Row> rows;
  for (const fs::path& dir : dirs) {
    if (!fs::is_directory(dir)) throw std::runtime_error("report --merge: no folder " + dir.string());
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file() && entry.path().extension() == ".csv") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      std::ifstream in(file);
      std::string line;
      std::getline(in, line);
      std::vector<std::string> header;
      std::stringstream hs(line);
      for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
      if (header.empty() || header[0] != "scene") {
        throw std::runtime_error("report --merge: " + file.string() + " is not a cps report CSV");
      }
      while (std::getline(in, line)) {
        if (line.empty()) continue;
        Row r;
        std::stringstream ls(line);
        std::string value;
        for (const std::string& c : header) {
          if (!std::getline(ls, value, ',')) value.clear();
          if (!value.empty()) r[c] = value;
        }
        rows.push_back(r);
      }
    }
  }
  return rows;
}

void write_report(const fs::path& dir, const std::vector<Row>& rows) {
  fs::create_directories(dir);
  std::map<std::string, std::vector<const Row*>> by_scene;
  std::vector<std::string> order;
  for (const Row& r : rows) {
    if (!by_scene.count(r.at("scene"))) order.push_back(r.at("scene"));
    by_scene[r.at("scene")].push_back(&r);
  }
  std::ostringstream md;
  md << "# Error against run time\n\n"
     << "Made by `cps report`. Each run steps the scene for its horizon with the settings in its "
        "row; the physics wall time per simulated second is the median of timing runs of the "
        "step alone (no metrics, no residual), after the error run as warm-up. Trajectory error: "
        "RMS distance of the bodies from a reference run (PGS, 256 iterations, 16 substeps, same "
        "push and friction model) at the trajectory time, kept short because contacts make "
        "these scenes chaotic. The LCP residual is the natural-map residual "
        "|lambda - clamp(lambda - (A lambda - b) / A_jj, c_min, c_max)| over every row of every "
        "solve. Substeps are steps per 1/60 s frame.\n\n"
     << "## Headline: error at the paper's settings and the time needed to halve it\n\n"
     << "The cheapest run with half the error is searched among every run of the scene (every "
        "solver, push and friction model), diverged runs left out.\n\n"
     << "| scene | measure | paper settings (pgs, baumgarte, fixed, 25 it, 60 Hz) | time (s/s) "
        "| cheapest run with half the error | its time (s/s) | time ratio |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& scene : order) {
    const std::string measure = primary_measure(scene);
    const Row* base = nullptr;
    for (const Row* r : by_scene[scene]) {
      if (is_paper_setting(*r)) base = r;
    }
    if (!base) continue;
    const double e0 = to_double(*base, measure);
    const double t0 = to_double(*base, "wall_s_per_sim_s");
    const Row* best = nullptr;
    for (const Row* r : by_scene[scene]) {
      if (r->at("diverged") == "1") continue;
      const double e = to_double(*r, measure);
      const double t = to_double(*r, "wall_s_per_sim_s");
      if (e <= 0.5 * e0 && std::isfinite(t) && (!best || t < to_double(*best, "wall_s_per_sim_s"))) best = r;
    }
    md << "| " << scene << " | " << measure << " | " << number(e0) << " | " << number(t0) << " | ";
    if (best) {
      const double t1 = to_double(*best, "wall_s_per_sim_s");
      md << best->at("solver") << ", " << best->at("push") << ", " << best->at("friction_model")
         << ", " << best->at("iterations") << " it, " << best->at("substeps")
         << " substeps: " << number(to_double(*best, measure)) << " | " << number(t1) << " | "
         << number(t1 / t0) << " |\n";
    } else {
      md << "none in this sweep | | |\n";
    }
  }
  md << "\n";
  for (const std::string& scene : order) {
    std::vector<Row> scene_rows;
    for (const Row* r : by_scene[scene]) scene_rows.push_back(*r);
    write_csv(dir / (scene + ".csv"), scene_rows);
    md << "## " << scene << "\n\nAll runs: [" << scene << ".csv](" << scene << ".csv).\n\n";
    for (const Measure& m : kMeasures) {
      if (plot_measure(dir, scene, m, by_scene[scene])) {
        md << "![" << scene << " " << m.column << "](" << scene << "_" << m.column << ".png)\n\n";
      }
    }
    const std::string measure = primary_measure(scene);
    md << "| solver | push | friction | iterations | substeps | time (s/s) | " << measure
       << " | residual RMS (N) | penetration max (m) | rod error max (m) | diverged |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row* r : by_scene[scene]) {
      const auto cell = [r](const std::string& c) {
        const auto it = r->find(c);
        return it == r->end() ? std::string() : it->second;
      };
      md << "| " << cell("solver") << " | " << cell("push") << " | " << cell("friction_model")
         << " | " << cell("iterations") << " | " << cell("substeps") << " | "
         << cell("wall_s_per_sim_s") << " | " << cell(measure) << " | " << cell("residual_rms_N")
         << " | " << cell("penetration_max_m") << " | " << cell("rod_error_max_m") << " | "
         << cell("diverged") << " |\n";
    }
    md << "\n";
  }
  md << "## Mass ratios: iterations each needs\n\n"
     << "A heavy cube resting on a light one on the ground (stress scenes mass_ratio_R), paper "
        "settings otherwise: the smallest PGS iteration count in 1, 2, 4, ..., 256 with which "
        "the pair still stands after 5 s with less than 1 cm of overlap (-1: none).\n\n"
     << "| mass ratio | iterations needed | penetration at 25 iterations after 5 s (m) |\n|---|---|---|\n";
  for (const double ratio : {10.0, 100.0, 1000.0}) {
    md << "| " << ratio << " | " << scenes::iterations_needed(ratio) << " | "
       << number(scenes::run_mass_ratio(ratio, 25, 5.0).final_penetration_m) << " |\n";
  }
  md << "\n";
  std::ofstream out(dir / "report.md");
  if (!out) throw std::runtime_error("report: cannot write " + (dir / "report.md").string());
  out << md.str();
}

namespace {

// The options of `cps report`.
struct ReportOptions {
  std::string scene = "all";
  std::string out = "out/report";
  bool quick = false;
  bool list = false;
  std::vector<std::string> merge;
  std::string run;
};

// The absolute path of this executable, for commands that must run anywhere.
std::string self_path() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "cps";
  path[n] = '\0';
  return path;
}

int run_report(const ReportOptions& o, int argc, char** argv) {
  // run.json in the report folder: what produced it (written after the report, atomically).
  const auto write_run_json = [&] {
    nlohmann::json merged = nlohmann::json::array();
    for (const std::string& m : o.merge) merged.push_back(m);
    const nlohmann::json info = run_info(
        "report", argc, argv,
        {{"scene", o.scene}, {"quick", o.quick}, {"repeats", o.quick ? 1 : 3}, {"merge", merged}});
    nlohmann::json j = info;
    j["tool"] = "cps";
    write_json_atomic(fs::path(o.out) / k_manifest_name, j);
  };
  const int repeats = o.quick ? 1 : 3;
  if (!o.merge.empty()) {
    std::vector<fs::path> dirs(o.merge.begin(), o.merge.end());
    const std::vector<Row> rows = read_rows(dirs);
    if (rows.empty()) throw UsageError("--merge: no report CSV found below the given folders");
    write_report(o.out, rows);
    write_run_json();
    std::printf("merged %zu runs into %s/report.md\n", rows.size(), o.out.c_str());
    return 0;
  }
  if (!o.run.empty()) {
    const RunSpec spec = RunSpec::parse(o.run);
    const Row row = execute_run(spec, repeats);
    fs::create_directories(o.out);
    write_csv(fs::path(o.out) / (spec.id() + ".csv"), {row});
    return 0;
  }
  const std::vector<RunSpec> runs = plan_runs(select_scenes(o.scene), o.quick);
  if (o.list) {
    const std::string exe = self_path();
    for (const RunSpec& r : runs) {
      std::printf("'%s' report --run %s --out '%s/runs'%s\n", exe.c_str(), r.id().c_str(),
                  o.out.c_str(), o.quick ? " --quick" : "");
    }
    std::printf("# when all have finished: '%s' report --merge '%s/runs' --out '%s'\n",
                exe.c_str(), o.out.c_str(), o.out.c_str());
    return 0;
  }
  std::vector<Row> rows;
  Progress progress("report " + o.scene, static_cast<long long>(runs.size()), "runs");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    rows.push_back(execute_run(runs[i], repeats));
    progress.update(static_cast<long long>(i + 1));
  }
  progress.finish();
  write_report(o.out, rows);
  write_run_json();
  std::printf("%zu runs: %s/report.md\n", rows.size(), o.out.c_str());
  return 0;
}

}  // namespace

Command add_report(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* sub = app.add_subcommand(
      "report", "error against run time: sweep solver settings, write CSV, plots, report.md");
  sub->add_option("scene", o->scene, "scene name, 'all' (the paper's) or 'stress'")
      ->capture_default_str();
  sub->add_option("--out", o->out, "output folder")->capture_default_str()->check(kNotEmpty);
  sub->add_flag("--quick", o->quick, "a reduced sweep: iterations 1, 4, 16, 25, 64 and 4 substeps, fixed friction only (the paper's five scenes: 120 runs, about 30 s on 2 cores)");
  sub->add_flag("--list-runs", o->list,
                "print one self-contained command per run, to spread the sweep over machines");
  sub->add_option("--merge", o->merge,
                  "combine the CSV files below these folders into one report in --out")
      ->check(kNotEmpty);
  sub->add_option("--run", o->run, "execute one run by its id (see --list-runs)")->check(kNotEmpty);
  return {sub, [o, argc, argv] { return run_report(*o, argc, argv); }};
}

}  // namespace cps::cli
