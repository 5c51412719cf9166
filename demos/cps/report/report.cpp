#include "report/report.h"

#include "command.h"
#include "options/options.h"
#include "output/output.h"
#include "options/progress.h"
#include "report/report_push.h"
#include "stress/mass_ratio.h"

#include <CLI/CLI.hpp>

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

// The name a scene's files start with: the scene's name, or for a scene file given by a path
// with folders ("runs/drop.json") its file name ("drop.json"), so that no file lands in another
// folder. One report holds one scene file, so file names stay distinct within it.
std::string file_stem(const std::string& scene) {
  return scene.find('/') == std::string::npos ? scene : fs::path(scene).filename().string();
}

}  // namespace

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

namespace {

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
  o.set("warm_start", spec.warm_start);
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

}  // namespace

bool sane_state(const World& world) {
  for (const Body& b : world.bodies()) {
    if (!b.x.allFinite() || !b.p.allFinite() || !b.l.allFinite() || !b.o.coeffs().allFinite()) {
      return false;
    }
    if (b.x.norm() > 1e6 || b.velocity().norm() > 1e6) return false;
  }
  return true;
}

namespace {

// The reference of the trajectory error: PGS with this many iterations and substeps per 1/60 s
// frame, and the run's own push and friction model.
constexpr int kReferenceIterations = 256;
constexpr int kReferenceSubsteps = 16;

// Positions of the movable bodies (m) once `spec` has been stepped to time t (s), or nullopt if
// the run blew up on the way (see sane_state).
std::optional<std::vector<Vec3>> positions_at(const RunSpec& spec, double t) {
  scenes::Run run = scenes::make_run(scene_of(spec), overrides_of(spec));
  run.world.step();  // at least one step, as every run
  while (run.world.time() + 0.5 * run.world.def().dt < t) {
    if (!sane_state(run.world)) return std::nullopt;
    run.world.step();
  }
  if (!sane_state(run.world)) return std::nullopt;
  return positions(run.world);
}

// RMS distance (m) between two lists of the same bodies' positions.
double rms_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double sq = 0.0;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) sq += (a[i] - b[i]).squaredNorm();
  return n ? std::sqrt(sq / static_cast<double>(n)) : 0.0;
}

// The reference of a run at its scene's trajectory time: the positions (nullopt if the reference
// blew up), and its own error estimate check_m (m), the RMS distance between the reference and
// the same run at half its substeps. For a first-order method halving dt halves the error, so
// the distance between the two is about the reference's own error; where contacts make the
// scene chaotic it is large, and trajectory errors below it mean nothing.
struct Reference {
  std::optional<std::vector<Vec3>> positions;
  double check_m = std::nan("");
};

// The reference of `spec` (its solver, iterations and substeps replaced); computed once per
// process and kept.
const Reference& reference_of(const RunSpec& spec) {
  static std::mutex mutex;
  static std::map<std::string, Reference> cache;
  RunSpec ref = spec;
  ref.solver = SolverKind::pgs;
  ref.iterations = kReferenceIterations;
  ref.substeps = kReferenceSubsteps;
  ref.warm_start = 0.0;  // one reference for the cold and the warm runs: the paper's start
  const std::lock_guard<std::mutex> lock(mutex);
  const auto it = cache.find(ref.id());
  if (it != cache.end()) return it->second;
  const double t = scene_of(ref).report_trajectory_time_s();
  Reference r;
  r.positions = positions_at(ref, t);
  RunSpec half = ref;
  half.substeps = kReferenceSubsteps / 2;
  const std::optional<std::vector<Vec3>> check = positions_at(half, t);
  if (r.positions && check) r.check_m = rms_distance(*r.positions, *check);
  return cache[ref.id()] = r;
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
      "scene", "solver", "push", "friction_model", "iterations", "substeps", "warm_start", "dt_s",
      "horizon_s", "diverged", "diverged_at_s", "wall_s_per_sim_s", "us_per_step", "timing_repeats",
      "trajectory_time_s", "trajectory_error_m", "reference_check_m", "phase_error_deg",
      "residual_max_N", "residual_rms_N", "penetration_max_m", "penetration_rms_m",
      "rod_error_max_m", "rod_error_rms_m", "energy_drift_rel", "sweep", "quick", "mass_ratio",
      "seconds", "held", "heavy_height_m", "light_offset_m", "overlap_m", "iterations_holding"};
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

// What the work-precision diagrams show: the CSV column, the axis label (with its unit), and the
// round-off floor, the value under which the measure shows double precision round-off rather
// than the method (see kFloorNotes). For the residual the floor is relative: floor times the
// scene's largest body weight m |g| (N).
struct Measure {
  const char* column;
  const char* label;  // what it is, with its unit
  const char* axis;   // the y axis' short label
  const char* unit;   // "" for a ratio
  double floor;
  bool floor_per_weight = false;
};
constexpr Measure kMeasures[] = {
    {"trajectory_error_m", "RMS distance from the reference run at the trajectory time (m)",
     "trajectory error (m)", "m", 1e-10},
    {"phase_error_deg", "largest phase error against the reduced-coordinate reference (deg)",
     "phase error (deg)", "deg", 1e-8},
    {"residual_rms_N", "RMS LCP residual over every row of every solve (N)", "residual RMS (N)",
     "N", 1e-12, true},
    {"penetration_max_m", "deepest contact penetration over the run (m)", "penetration (m)", "m",
     1e-10},
    {"rod_error_max_m", "largest rod length error over the run (m)", "rod error (m)", "m", 1e-10},
    {"energy_drift_rel", "largest relative energy drift |E(t) / E(0) - 1|", "|E / E0 - 1|", "",
     1e-12},
    {"metric.max_speed_mps",
     "largest body speed at the end of the run (m/s; at rest, 0, is right)", "speed (m/s)", "m/s",
     1e-10},
};

// Why the floors are where they are, for report.md.
constexpr const char* kFloorNotes =
    "values under a measure's round-off floor are drawn on the floor (dotted line) with their "
    "own mark: double precision carries 2.2e-16 of relative round-off per operation, so there "
    "they show round-off, not the method. Lengths (trajectory error, penetration, rod error): "
    "1e-10 m; positions metres from the origin carry about 1e-15 m per operation, and a run "
    "takes 1e3 to 1e5 steps of many operations each. LCP residual: 1e-12 of the scene's largest "
    "body weight m |g| (N); a solve exact to round-off leaves about 1e-16 of the forces solved "
    "for. Phase error: 1e-8 deg (2e-10 rad); the pendulum wave's phases grow to 630 rad over "
    "3720 steps, each adding about 1e-13 rad. Energy drift: 1e-12, energies summed over 50 "
    "bodies for 3720 steps. Speed: 1e-10 m/s.";

// The largest weight m |g| (N) among the movable bodies of `scene`; 1 N without gravity or for a
// scene this build does not know.
double largest_weight(const std::string& scene) {
  const scenes::Scene* s = scenes::find_scene(scene);
  if (!s) return 1.0;
  const scenes::Run run = scenes::make_run(*s);
  double w = 0.0;
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) w = std::max(w, b.mass * run.world.def().gravity.norm());
  }
  return w > 0.0 ? w : 1.0;
}

// The round-off floor of measure m in `scene` (the measure's unit).
double floor_of(const Measure& m, const std::string& scene) {
  return m.floor_per_weight ? m.floor * largest_weight(scene) : m.floor;
}

// The error measure the headline of the scene called `scene` uses (its Scene::report); the
// default one for a name no scene has (a CSV of an older build).
std::string primary_measure(const std::string& scene) {
  const scenes::Scene* s = scenes::find_scene(scene);
  return std::string(s ? s->report.primary_measure : scenes::ReportTraits{}.primary_measure);
}

std::string variant_of(const Row& r) {
  return r.at("solver") + " " + r.at("push") + " " + r.at("friction_model");
}

// The warm start factor of a row (dimensionless); 0 (cold) where the column is missing or
// empty (a CSV of a build before warm starting).
double warm_of(const Row& r) {
  const double w = to_double(r, "warm_start");
  return std::isnan(w) ? 0.0 : w;
}

// The paper's settings: PGS, Baumgarte push, fixed friction, 25 iterations, 1 substep (60 Hz),
// cold start.
bool is_paper_setting(const Row& r) {
  return r.at("solver") == "pgs" && r.at("push") == "baumgarte" &&
         r.at("friction_model") == "fixed" && r.at("iterations") == "25" &&
         r.at("substeps") == "1" && warm_of(r) == 0.0;
}

}  // namespace

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

std::string gp_text(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

namespace {

// The place of a setting's name in the order the diagrams' panels take (unknown names last).
int rank_of(const std::string& value, std::initializer_list<const char*> order) {
  int i = 0;
  for (const char* o : order) {
    if (value == o) return i;
    ++i;
  }
  return i;
}

// The place of a push method's name in the table's order of the parameter push (the order of
// the diagrams' panels and of the tables); names the table does not have (a CSV of another
// build) after them.
int push_rank(const std::string& value) {
  const auto choices = parameter("push").choices;
  int i = 0;
  for (const Choice& c : choices) {
    if (value == c.name) return i;
    ++i;
  }
  return i;
}

// One point of a diagram: physics time (s/s), the value drawn, and its label.
struct PlotPoint {
  double x = 0.0;
  double y = 0.0;
  std::string label;
};

// One panel of a work-precision diagram: the runs of one solver, push and friction model.
struct Panel {
  std::string title;
  std::vector<PlotPoint> iterations;  // 1 substep, by iteration count (solid line)
  // The warm-started iteration lines (1 substep, by iteration count), by warm start factor (one
  // per factor of the whole diagram, Diagram::warm_factors; empty where the panel has none).
  std::vector<std::vector<PlotPoint>> warm;
  std::vector<PlotPoint> substeps;    // 25 iterations, by substep count (dashed line)
  std::vector<PlotPoint> paper;       // the paper's settings (25 iterations, 1 substep)
  std::vector<PlotPoint> clamped;     // values under the floor, drawn on it
  std::vector<PlotPoint> diverged;    // drawn at the top edge (y set once the range is known)
  // Labels, placed by place_labels (x, y: the label's centre): the first and last point of the
  // iteration line, the last of the substep line, every diverged run.
  std::vector<PlotPoint> labels_it;
  std::vector<PlotPoint> labels_ss;
  std::vector<PlotPoint> labels_div;
  double reference = std::nan("");    // the reference's own error (trajectory error only), or NaN
};

// A work-precision diagram of one measure for one scene: a panel per solver, push and friction
// model, all on the same axes.
struct Diagram {
  std::vector<Panel> panels;
  double floor = 0.0;
  bool show_floor = false;
  bool any_clamped = false;
  bool any_diverged = false;
  bool any_reference = false;
  std::vector<double> warm_factors;  // the warm start factors (> 0) of any run, ascending
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;  // y_hi: the top edge
};

// Sizes in a panel's frame, as fractions of its width (u) and height (v): a panel's frame is
// about 480 x 240 pixels, a label character (font size 8) about 5 x 11 pixels.
constexpr double kCharU = 5.0 / 480.0, kLabelV = 11.0 / 240.0;
constexpr double kPointU = 6.0 / 480.0, kPointV = 6.0 / 240.0;  // half a point mark, with a gap

// Places a panel's labels so that no label overlaps another label, a point mark or the frame's
// edge: each takes the first free place of eight around its point (above, below, right, left,
// then the corners; diverged runs' labels only under their mark, further down if need be), or
// the least crowded one. The labels' positions are in data coordinates (log-log axes).
void place_labels(Panel& p, const Diagram& d);

// The diagram of measure m over the rows of one scene, or nullopt if no run that finished has a
// value of it (floor: the measure's round-off floor in its unit).
std::optional<Diagram> make_diagram(const Measure& m, double floor,
                                    const std::vector<const Row*>& rows) {
  const auto key_of = [](const Row& r) {
    return std::make_tuple(rank_of(r.at("friction_model"), {"fixed", "coupled"}),
                           push_rank(r.at("push")),
                           rank_of(r.at("solver"), {"pgs", "jacobi"}), variant_of(r));
  };
  std::map<std::tuple<int, int, int, std::string>, std::vector<const Row*>> by_panel;
  for (const Row* r : rows) by_panel[key_of(*r)].push_back(r);
  Diagram d;
  d.floor = floor;
  for (const Row* r : rows) {
    const double w = warm_of(*r);
    if (w != 0.0 &&
        std::find(d.warm_factors.begin(), d.warm_factors.end(), w) == d.warm_factors.end()) {
      d.warm_factors.push_back(w);
    }
  }
  std::sort(d.warm_factors.begin(), d.warm_factors.end());
  double raw_min = kInfinity, y_max = 0.0, x_min = kInfinity, x_max = 0.0;
  bool any_value = false;
  for (auto& [key, panel_rows] : by_panel) {
    Panel p;
    const Row& first = *panel_rows.front();
    p.title = first.at("solver") + ", " + first.at("push") + " push, " +
              first.at("friction_model") + " friction";
    const auto count = [](const Row& r, const char* c) { return std::atoi(r.at(c).c_str()); };
    std::vector<const Row*> sorted = panel_rows;
    std::sort(sorted.begin(), sorted.end(), [&](const Row* a, const Row* b) {
      return std::make_pair(count(*a, "substeps"), count(*a, "iterations")) <
             std::make_pair(count(*b, "substeps"), count(*b, "iterations"));
    });
    std::vector<std::pair<int, PlotPoint>> it_line, ss_line;
    std::vector<std::vector<std::pair<int, PlotPoint>>> warm_lines(d.warm_factors.size());
    for (const Row* r : sorted) {
      const double t = to_double(*r, "wall_s_per_sim_s");
      if (!(t > 0.0)) continue;
      const int it = count(*r, "iterations");
      const int ss = count(*r, "substeps");
      const double w = warm_of(*r);
      const std::string label =
          (ss == 1 ? std::to_string(it) + " it" : std::to_string(ss) + " ss") +
          (w != 0.0 ? ", ws " + shortest_decimal(w) : std::string());
      if (r->at("diverged") == "1") {
        p.diverged.push_back({t, 0.0, label});
        d.any_diverged = true;
        x_min = std::min(x_min, t);
        x_max = std::max(x_max, t);
        continue;
      }
      const double e = to_double(*r, m.column);
      if (std::isnan(e)) continue;
      any_value = true;
      raw_min = std::min(raw_min, e);
      const PlotPoint point{t, std::max(e, floor), label};
      if (e < floor) {
        p.clamped.push_back(point);
        d.any_clamped = true;
      }
      y_max = std::max(y_max, point.y);
      x_min = std::min(x_min, t);
      x_max = std::max(x_max, t);
      if (w != 0.0) {
        // Warm runs: the iteration line of their factor only (the sweep has no warm substeps).
        const auto k = std::find(d.warm_factors.begin(), d.warm_factors.end(), w);
        const auto line = static_cast<std::size_t>(k - d.warm_factors.begin());
        if (ss == 1) warm_lines[line].emplace_back(it, point);
        continue;
      }
      if (ss == 1) it_line.emplace_back(it, point);
      if (it == 25) ss_line.emplace_back(ss, point);
      if (ss == 1 && it == 25) p.paper.push_back(point);
    }
    for (auto& line : warm_lines) {
      std::sort(line.begin(), line.end(),
                [](const auto& a, const auto& b) { return a.first < b.first; });
      p.warm.emplace_back();
      for (const auto& [n, point] : line) p.warm.back().push_back(point);
    }
    std::sort(it_line.begin(), it_line.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::sort(ss_line.begin(), ss_line.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [n, point] : it_line) p.iterations.push_back(point);
    for (const auto& [n, point] : ss_line) p.substeps.push_back(point);
    if (!p.iterations.empty()) p.labels_it.push_back(p.iterations.front());
    if (p.iterations.size() > 1) p.labels_it.push_back(p.iterations.back());
    if (p.substeps.size() > 1) p.labels_ss.push_back(p.substeps.back());
    if (std::string(m.column) == "trajectory_error_m") {
      // A reference whose own error is under the floor (the same positions to round-off) has
      // no line: it would lie on the floor's.
      const double ref = to_double(first, "reference_check_m");
      if (ref >= floor) {
        p.reference = ref;
        d.any_reference = true;
        y_max = std::max(y_max, p.reference);
      }
    }
    d.panels.push_back(std::move(p));
  }
  if (!any_value) return std::nullopt;
  // The floor is drawn when a value comes within two decades of it; otherwise it would only
  // stretch the axis.
  d.show_floor = raw_min < 100.0 * floor;
  double y_min = kInfinity;
  for (const Panel& p : d.panels) {
    for (const auto* line : {&p.iterations, &p.substeps}) {
      for (const PlotPoint& q : *line) y_min = std::min(y_min, q.y);
    }
    for (const auto& line : p.warm) {
      for (const PlotPoint& q : line) y_min = std::min(y_min, q.y);
    }
    if (p.reference > 0.0) y_min = std::min(y_min, p.reference);
  }
  if (d.show_floor) y_min = std::min(y_min, floor / 3.0);  // room for the floor's label
  d.y_lo = y_min / 3.0;
  d.y_hi = std::max(y_max, y_min) * 3.0;
  if (d.any_diverged) d.y_hi *= 10.0;  // a decade of room: the diverged marks sit on the top edge
  for (Panel& p : d.panels) {
    for (PlotPoint& q : p.diverged) q.y = d.y_hi;
  }
  d.x_lo = x_min / 1.5;
  d.x_hi = x_max * 1.5;
  for (Panel& p : d.panels) place_labels(p, d);
  return d;
}

void place_labels(Panel& p, const Diagram& d) {
  const double lu = std::log(d.x_hi / d.x_lo), lv = std::log(d.y_hi / d.y_lo);
  const auto u_of = [&](double x) { return std::log(x / d.x_lo) / lu; };
  const auto v_of = [&](double y) { return std::log(y / d.y_lo) / lv; };
  struct Box {
    double u0, u1, v0, v1;
  };
  std::vector<Box> taken;
  for (const auto* list : {&p.iterations, &p.substeps, &p.clamped, &p.diverged, &p.paper}) {
    const double grow = list == &p.paper ? 1.7 : 1.0;  // the paper's ring is larger
    for (const PlotPoint& q : *list) {
      const double u = u_of(q.x), v = v_of(q.y);
      taken.push_back({u - grow * kPointU, u + grow * kPointU, v - grow * kPointV, v + grow * kPointV});
    }
  }
  for (const auto& line : p.warm) {
    for (const PlotPoint& q : line) {
      const double u = u_of(q.x), v = v_of(q.y);
      taken.push_back({u - kPointU, u + kPointU, v - kPointV, v + kPointV});
    }
  }
  // The floor's and the reference's lines, as thin boxes across the frame.
  for (const double y : {d.show_floor ? d.floor : 0.0, p.reference}) {
    if (y > 0.0) taken.push_back({0.0, 1.0, v_of(y) - 0.01, v_of(y) + 0.01});
  }
  const auto overlap = [](const Box& a, const Box& b) {
    const double du = std::min(a.u1, b.u1) - std::max(a.u0, b.u0);
    const double dv = std::min(a.v1, b.v1) - std::max(a.v0, b.v0);
    return du > 0.0 && dv > 0.0 ? du * dv : 0.0;
  };
  const auto place = [&](const PlotPoint& q, bool under_only) {
    const double u = u_of(q.x), v = v_of(q.y);
    const double hw = 0.5 * kCharU * static_cast<double>(q.label.size()), hh = 0.5 * kLabelV;
    const double du = kPointU + hw, dv = kPointV + hh;
    std::vector<std::pair<double, double>> offsets;
    if (under_only) {
      for (int k = 1; k <= 4; ++k) offsets.emplace_back(0.0, -dv - (k - 1) * 2.0 * hh);
    } else {
      offsets = {{0.0, dv}, {0.0, -dv}, {du, 0.0}, {-du, 0.0},
                 {du, dv}, {-du, dv}, {du, -dv}, {-du, -dv}};
    }
    Box best{};
    double best_cost = kInfinity;
    for (const auto& [ou, ov] : offsets) {
      const Box b{u + ou - hw, u + ou + hw, v + ov - hh, v + ov + hh};
      double cost = 0.0;
      for (const Box& t : taken) cost += overlap(b, t);
      // Outside the frame counts as crowded as a full overlap.
      if (b.u0 < 0.0 || b.u1 > 1.0 || b.v0 < 0.0 || b.v1 > 1.0) cost += 4.0 * hw * hh;
      if (cost < best_cost) best_cost = cost, best = b;
      if (cost == 0.0) break;
    }
    taken.push_back(best);
    return PlotPoint{d.x_lo * std::exp(0.5 * (best.u0 + best.u1) * lu),
                     d.y_lo * std::exp(0.5 * (best.v0 + best.v1) * lv), q.label};
  };
  std::vector<PlotPoint> diverged = p.diverged;
  std::sort(diverged.begin(), diverged.end(),
            [](const PlotPoint& a, const PlotPoint& b) { return a.x < b.x; });
  for (const PlotPoint& q : diverged) p.labels_div.push_back(place(q, true));
  std::vector<PlotPoint> it = std::move(p.labels_it), ss = std::move(p.labels_ss);
  p.labels_it.clear();
  p.labels_ss.clear();
  for (const PlotPoint& q : it) p.labels_it.push_back(place(q, false));
  for (const PlotPoint& q : ss) p.labels_ss.push_back(place(q, false));
}

// The diagram's data: one gnuplot index block per non-empty list, in the order plot_script
// reads them; per line x, y and a "label" (for the label lists, x and y are where the label's
// centre goes).
void write_plot_data(std::ostream& out, const Diagram& d) {
  for (const Panel& p : d.panels) {
    std::vector<const std::vector<PlotPoint>*> lists = {&p.iterations};
    for (const auto& line : p.warm) lists.push_back(&line);
    for (const auto* list : {&p.substeps, &p.paper, &p.clamped, &p.diverged, &p.labels_it,
                             &p.labels_ss, &p.labels_div}) {
      lists.push_back(list);
    }
    for (const auto* list : lists) {
      if (list->empty()) continue;
      for (const PlotPoint& q : *list) out << q.x << " " << q.y << " \"" << q.label << "\"\n";
      out << "\n\n";
    }
  }
}

// True if the label of the panel's reference line goes under the line: where most of the
// panel's points lie above it, unless the line is near the frame's bottom (near its top, always).
bool label_under_reference(const Panel& p, const Diagram& d) {
  const double v = std::log(p.reference / d.y_lo) / std::log(d.y_hi / d.y_lo);
  if (v < 0.12) return false;
  if (v > 0.88) return true;
  int above = 0, below = 0;
  for (const auto* line : {&p.iterations, &p.substeps}) {
    for (const PlotPoint& q : *line) (q.y > p.reference ? above : below) += 1;
  }
  for (const auto& line : p.warm) {
    for (const PlotPoint& q : line) (q.y > p.reference ? above : below) += 1;
  }
  return above > below;
}

// The style of the warm-started iteration line of the k-th warm start factor: its own colour,
// dash and point, so that it stays apart from the cold line (blue, solid, discs) and the
// substep line (pink, dashed, squares) in the same panel.
struct WarmStyle {
  const char* colour;
  int dash;
  int point;
};
constexpr WarmStyle kWarmStyles[] = {
    {"#2ca02c", 4, 9}, {"#ff7f0e", 5, 13}, {"#9467bd", 6, 11}, {"#8c564b", 3, 3}};
const WarmStyle& warm_style(std::size_t k) {
  return kWarmStyles[k % (sizeof kWarmStyles / sizeof kWarmStyles[0])];
}
std::string warm_line_style(std::size_t k) {
  const WarmStyle& w = warm_style(k);
  return "lw 1.5 dt " + std::to_string(w.dash) + " pt " + std::to_string(w.point) +
         " ps 0.8 lc rgb '" + w.colour + "'";
}

// The rows of the key under the panels (the warm lines' entries take a third) and its height
// (pixels).
int key_rows(const Diagram& d) { return d.warm_factors.empty() ? 2 : 3; }
double key_height(const Diagram& d) { return 10.0 + 30.0 * key_rows(d); }

// The gnuplot commands that draw the diagram from `data` (written by write_plot_data) into the
// current terminal: a grid of panels (pgs left, jacobi right, a row per push and friction
// model) on shared axes, and a key below them.
std::string plot_script(const Diagram& d, const fs::path& data, const std::string& title,
                        const Measure& m, int height) {
  std::ostringstream gp;
  const int n = static_cast<int>(d.panels.size());
  const int cols = n > 1 ? 2 : 1;
  const int rows = (n + cols - 1) / cols;
  const double title_h = 40.0 / height, key_h = key_height(d) / height;
  const double panel_w = 1.0 / cols, panel_h = (1.0 - title_h - key_h) / rows;
  // x tics at 1, 2 and 5 per decade: the time axis spans one or two decades.
  std::string xtics;
  for (double decade = std::pow(10.0, std::floor(std::log10(d.x_lo))); decade < d.x_hi; decade *= 10.0) {
    for (const double f : {1.0, 2.0, 5.0}) {
      if (f * decade >= d.x_lo && f * decade <= d.x_hi) {
        xtics += (xtics.empty() ? "" : ", ") + number(f * decade);
      }
    }
  }
  gp << "reset\nset multiplot\n"
     << "set logscale xy\nset format x '%g'\nset format y '1e%T'\n"
     << "set xrange [" << d.x_lo << ":" << d.x_hi << "]\nset yrange [" << d.y_lo << ":" << d.y_hi
     << "]\nset grid xtics ytics lc rgb '#d8d8d8'\nset tics font ',8'\nunset key\n"
     << (xtics.empty() ? std::string() : "set xtics (" + xtics + ")\n")
     << "set lmargin 9\nset rmargin 2\nset tmargin 1.8\nset bmargin 2.6\n"
     << "set label 100 " << gp_text(title) << " at screen 0.5, screen " << 1.0 - 0.5 * title_h
     << " center font ',12'\n";
  if (d.show_floor) {
    gp << "set arrow 1 from graph 0, first " << d.floor << " to graph 1, first " << d.floor
       << " nohead dt 3 lw 1.2 lc rgb 'gray30' back\n"
       << "set label 1 'round-off floor' at graph 0.02, first " << d.floor
       << " offset 0,-0.7 font ',7' tc rgb 'gray30'\n";
  }
  int index = 0;
  for (int i = 0; i < n; ++i) {
    const Panel& p = d.panels[static_cast<std::size_t>(i)];
    const int col = i % cols, row = i / cols;
    gp << "set origin " << col * panel_w << ", " << key_h + (rows - 1 - row) * panel_h << "\n"
       << "set size " << panel_w << ", " << panel_h << "\n"
       << "set title " << gp_text(p.title) << " font ',10' offset 0,-0.4\n"
       << (row == rows - 1 ? "set xlabel 'physics wall time per simulated second (s/s)' "
                             "font ',9' offset 0,0.4\n"
                           : "unset xlabel\n")
       << (col == 0 ? "set ylabel " + gp_text(m.axis) + " font ',9' offset 1,0\n" : "unset ylabel\n");
    if (p.reference > 0.0) {
      gp << "set arrow 2 from graph 0, first " << p.reference << " to graph 1, first "
         << p.reference << " nohead dt 4 lw 1.2 lc rgb '#b8860b' back\n"
         << "set label 2 'reference''s own error' at graph 0.02, first " << p.reference
         << " offset 0," << (label_under_reference(p, d) ? "-0.7" : "0.7")
         << " font ',7' tc rgb '#b8860b'\n";
    } else {
      gp << "unset arrow 2\nunset label 2\n";
    }
    std::vector<std::string> parts;
    // Adds the plot of the next index block (list, if not empty).
    const auto block = [&](const std::vector<PlotPoint>& list, const std::string& style) {
      if (list.empty()) return;
      parts.push_back((parts.empty() ? gp_text(data.string()) : std::string("''")) + " index " +
                      std::to_string(index++) + " " + style);
    };
    block(p.iterations, "using 1:2 with linespoints lw 1.5 pt 7 ps 0.7 lc rgb '#1f77b4'");
    for (std::size_t k = 0; k < p.warm.size(); ++k) {
      block(p.warm[k], "using 1:2 with linespoints " + warm_line_style(k));
    }
    block(p.substeps, "using 1:2 with linespoints lw 1.5 dt 2 pt 5 ps 0.7 lc rgb '#e377c2'");
    block(p.paper, "using 1:2 with points pt 6 ps 2.2 lw 1.5 lc rgb 'black'");
    block(p.clamped, "using 1:2 with points pt 10 ps 1.6 lw 1.5 lc rgb 'black'");
    block(p.diverged, "using 1:2 with points pt 2 ps 1.8 lw 2.5 lc rgb '#d62728'");
    block(p.labels_it, "using 1:2:3 with labels font ',8' tc rgb '#1f77b4'");
    block(p.labels_ss, "using 1:2:3 with labels font ',8' tc rgb '#c0399c'");
    block(p.labels_div, "using 1:2:3 with labels font ',8' tc rgb '#d62728'");
    gp << "plot ";
    for (std::size_t k = 0; k < parts.size(); ++k) gp << (k ? ", \\\n     " : "") << parts[k];
    gp << "\n";
    if (i == 0) gp << "unset label 100\n";
  }
  // The key: a frameless plot of nothing under the panels.
  gp << "unset arrow\nunset label\nunset title\nunset xlabel\nunset ylabel\nunset logscale\n"
     << "unset border\nunset tics\nunset grid\nset origin 0, 0\nset size 1, " << key_h << "\n"
     << "set lmargin 0\nset rmargin 0\nset tmargin 0\nset bmargin 0\n"
     << "set xrange [0:1]\nset yrange [0:1]\n"
     << "set key center center horizontal maxrows " << key_rows(d)
     << " width 1 samplen 3 font ',9'\nplot "
     << "NaN with linespoints lw 1.5 pt 7 lc rgb '#1f77b4' title 'iterations, 1 substep (60 Hz)'";
  for (std::size_t k = 0; k < d.warm_factors.size(); ++k) {
    gp << ", NaN with linespoints " << warm_line_style(k) << " title "
       << gp_text("iterations, warm start " + shortest_decimal(d.warm_factors[k]));
  }
  gp << ", NaN with linespoints lw 1.5 dt 2 pt 5 lc rgb '#e377c2' title "
        "'substeps per 1/60 s frame, 25 iterations'"
     << ", NaN with points pt 6 ps 2 lw 1.5 lc rgb 'black' title 'the paper''s settings'";
  if (d.any_diverged) {
    gp << ", NaN with points pt 2 ps 1.5 lw 2.5 lc rgb '#d62728' title "
          "'diverged (on the top edge; time until it diverged)'";
  }
  if (d.show_floor) {
    gp << ", NaN with lines dt 3 lw 1.2 lc rgb 'gray30' title "
       << gp_text("round-off floor: " + number(d.floor) + " " + m.unit);
  }
  if (d.any_clamped) {
    gp << ", NaN with points pt 10 ps 1.5 lw 1.5 lc rgb 'black' title "
          "'under the floor (drawn on it)'";
  }
  if (d.any_reference) {
    gp << ", NaN with lines dt 4 lw 1.2 lc rgb '#b8860b' title "
          "'reference''s own error (16 vs 8 substeps)'";
  }
  gp << "\nunset multiplot\n";
  return gp.str();
}

// One diagram DIR/SCENE_<measure>.png, .svg and .pdf (the PDF through gnuplot's pdfcairo
// terminal, its text as text, for a paper): the measure against physics time, log-log, in
// small multiples (see plot_script). False if no run has a value of the measure.
bool plot_measure(const fs::path& dir, const std::string& scene, const Measure& m,
                  const std::vector<const Row*>& rows, const std::string& title_note) {
  const std::optional<Diagram> diagram = make_diagram(m, floor_of(m, scene), rows);
  if (!diagram) return false;
  const std::string stem = file_stem(scene) + "_" + m.column;
  const fs::path data = dir / "plots" / (stem + ".dat");
  const fs::path script = dir / "plots" / (stem + ".gp");
  {
    std::ostringstream out;
    write_plot_data(out, *diagram);
    write_text_atomic(data, out.str());
  }
  const int rows_of_panels = (static_cast<int>(diagram->panels.size()) + 1) / 2;
  const int width = 1100,
            height = 40 + static_cast<int>(key_height(*diagram)) + 300 * rows_of_panels;
  const std::string title = scene + ": " + m.label + title_note;
  const std::string body = plot_script(*diagram, data, title, m, height);
  // gnuplot writes the pictures into temporaries of this run, renamed once it has succeeded.
  AtomicFile png(dir / (stem + ".png"));
  AtomicFile svg(dir / (stem + ".svg"));
  AtomicFile pdf(dir / (stem + ".pdf"));
  png.hand_over();
  svg.hand_over();
  pdf.hand_over();
  std::ostringstream gp;
  gp << "set terminal pngcairo size " << width << "," << height << " font ',10' noenhanced\n"
     << "set output '" << png.temporary().string() << "'\n" << body;
  gp << "set terminal svg size " << width << "," << height << " font ',10' noenhanced\n"
     << "set output '" << svg.temporary().string() << "'\n" << body;
  // The PDF at 100 pixels of the PNG per inch, so its 10 pt text sits as in the PNG.
  gp << "set terminal pdfcairo size " << width / 100.0 << "in," << height / 100.0
     << "in font ',10' noenhanced\n"
     << "set output '" << pdf.temporary().string() << "'\n" << body << "unset output\n";
  write_text_atomic(script, gp.str());
  run_gnuplot(script);
  png.commit();
  svg.commit();
  pdf.commit();
  return true;
}


// How far the heavy cube's centre may be from its stacked height 3 h and the pair still count
// as held (m): h / 2, a light cube crushed by under a quarter of its edge. Squeezed out from
// under, the heavy cube drops to h, 2 h lower.
constexpr double kHeldHeightTolerance = 0.5 * scenes::kMassRatioHalfEdge;
// The heavy cube's stacked height (m): on the light cube, on the ground.
constexpr double kStackedHeight = 3.0 * scenes::kMassRatioHalfEdge;

// The pair in `world` (made by scenes::populate_mass_ratio: body 1 light, body 2 heavy). Held:
// the light cube is still between the heavy cube and the ground, that is its centre is within
// h of the heavy cube's vertical axis (the heavy cube's centre of mass is over the light cube's
// top face: it rests on it, not beside it) and the heavy cube's centre is within
// kHeldHeightTolerance of its stacked height.
PairOutcome pair_outcome(const World& world) {
  PairOutcome o;
  if (!sane_state(world)) return o;
  const Vec3& light = world.body(1).x;
  const Vec3& heavy = world.body(2).x;
  o.finite = true;
  o.light_offset_m = std::hypot(light.x() - heavy.x(), light.z() - heavy.z());
  o.heavy_height_m = heavy.y();
  o.overlap_m = scenes::max_penetration_now(world);
  o.held = o.light_offset_m <= scenes::kMassRatioHalfEdge &&
           std::abs(o.heavy_height_m - kStackedHeight) <= kHeldHeightTolerance;
  return o;
}

}  // namespace

PairOutcome run_pair(double ratio, SolverKind solver, PushMode push, int iterations,
                     double seconds) {
  WorldDef def = scenes::mass_ratio_world_def();
  def.solver = solver;
  def.push = push;
  def.iterations = iterations;
  World world(def);
  scenes::populate_mass_ratio(world, ratio);
  while (world.time() + 0.5 * def.dt < seconds) {
    world.step();
    if (!sane_state(world)) return {};
  }
  return pair_outcome(world);
}

namespace {

// The mass ratio table: for each ratio of kMassRatios and each solver and push, the pair after
// kPairSeconds at 25 iterations, and the iteration counts of 1, 2, 4, ..., 256 with which it
// holds with under 1 cm of overlap (space-separated; holding need not be monotone in the count).
// One row each (columns mass_ratio, solver, push, iterations, seconds, held, heavy_height_m,
// light_offset_m, overlap_m, iterations_holding). The pushes are every choice of the world
// parameter push, in the table's order.
std::vector<Row> mass_ratio_rows() {
  std::vector<Row> rows;
  for (const double ratio : kMassRatios) {
    for (const Choice& c : parameter("push").choices) {
      const auto push = static_cast<PushMode>(c.value);
      for (const SolverKind solver : {SolverKind::pgs, SolverKind::jacobi}) {
        const PairOutcome o = run_pair(ratio, solver, push, 25, kPairSeconds);
        std::string holding;
        for (int n = 1; n <= 256; n *= 2) {
          const PairOutcome q = run_pair(ratio, solver, push, n, kPairSeconds);
          if (q.held && q.overlap_m < 0.01) holding += (holding.empty() ? "" : " ") + std::to_string(n);
        }
        Row r;
        r["mass_ratio"] = number(ratio);
        r["solver"] = name(solver);
        r["push"] = name(push);
        r["iterations"] = "25";
        r["seconds"] = number(kPairSeconds);
        r["held"] = o.held ? "1" : "0";
        r["heavy_height_m"] = number(o.heavy_height_m);
        r["light_offset_m"] = number(o.light_offset_m);
        r["overlap_m"] = number(o.overlap_m);
        r["iterations_holding"] = holding;
        rows.push_back(r);
      }
    }
  }
  return rows;
}

// The id (RunSpec::id) of the run a CSV row holds.
std::string id_of(const Row& r) {
  const double w = warm_of(r);
  return r.at("scene") + "." + r.at("solver") + "." + r.at("push") + "." +
         r.at("friction_model") + ".it" + r.at("iterations") + ".ss" + r.at("substeps") +
         (w != 0.0 ? ".ws" + shortest_decimal(w) : std::string());
}

// A human label of a CSV column: the diagram's label of a measure, else the column's name.
std::string label_of(const std::string& column) {
  for (const Measure& m : kMeasures) {
    if (column == m.column) return m.label;
  }
  return column;
}

// The iteration count of the paper's settings (PGS, Baumgarte, fixed friction, 1 substep).
constexpr int kPaperIterations = 25;

// The table "Warm starting: what PGS needs to reach the paper's error" of one scene, from its
// rows: for the cold start 0 and each warm start factor (kReportWarmStarts and any other in the
// rows), the fewest iterations at the paper's other settings (PGS, Baumgarte, fixed friction,
// 1 substep) whose value of the scene's primary measure (primary_measure) is at most the
// paper's run's (25 iterations, cold); that run's wall time per simulated second and its ratio
// to the paper's run's; and the iterations saved, 25 minus that count. Diverged runs and runs
// without a value never count; "none in this sweep" where no run of the factor reaches it.
void write_warm_table(std::ostream& md, const std::string& scene,
                      const std::vector<const Row*>& rows) {
  const std::string measure = primary_measure(scene);
  md << "### Warm starting: what PGS needs to reach the paper's error\n\n";
  const Row* base = nullptr;
  for (const Row* r : rows) {
    if (is_paper_setting(*r)) base = r;
  }
  if (!base || base->at("diverged") == "1" || std::isnan(to_double(*base, measure)) ||
      !(to_double(*base, "wall_s_per_sim_s") > 0.0)) {
    md << "The paper's run (PGS, Baumgarte, fixed friction, " << kPaperIterations
       << " it, 1 substep, warm start 0) is "
       << (base ? "diverged or without a value of " + label_of(measure)
                : std::string("not in this sweep"))
       << ": nothing to compare with.\n\n";
    return;
  }
  const double e0 = to_double(*base, measure);
  const double t0 = to_double(*base, "wall_s_per_sim_s");
  md << "The fewest iterations at the paper's other settings (PGS, Baumgarte, fixed friction, "
        "1 substep) with which a run's " << label_of(measure) << " is at most the paper's run's ("
     << kPaperIterations << " it, warm start 0): " << number(e0) << ", in " << number(t0)
     << " s/s. Iterations saved: " << kPaperIterations
     << " minus that count. Diverged runs never count.";
  if (measure == "trajectory_error_m" && e0 < to_double(*base, "reference_check_m")) {
    md << " The paper's value is under its reference's own error ("
       << number(to_double(*base, "reference_check_m"))
       << " m): the counts compare differences the reference does not resolve.";
  }
  md << "\n\n| warm start factor | fewest iterations | its " << label_of(measure)
     << " | its time (s/s) | time ratio to the paper's run | iterations saved |\n"
        "|---|---|---|---|---|---|\n";
  std::vector<double> factors = {0.0};
  for (const double w : kReportWarmStarts) factors.push_back(w);
  for (const Row* r : rows) {
    if (std::find(factors.begin(), factors.end(), warm_of(*r)) == factors.end()) {
      factors.push_back(warm_of(*r));
    }
  }
  std::sort(factors.begin(), factors.end());
  for (const double w : factors) {
    const Row* fewest = nullptr;
    for (const Row* r : rows) {
      if (r->at("solver") != "pgs" || r->at("push") != "baumgarte" ||
          r->at("friction_model") != "fixed" || r->at("substeps") != "1" || warm_of(*r) != w ||
          r->at("diverged") == "1") {
        continue;
      }
      const double e = to_double(*r, measure);
      if (!(e <= e0)) continue;
      const int n = std::atoi(r->at("iterations").c_str());
      if (!fewest || n < std::atoi(fewest->at("iterations").c_str())) fewest = r;
    }
    md << "| " << shortest_decimal(w) << (w == 0.0 ? " (cold, the paper's)" : "") << " | ";
    if (!fewest) {
      md << "none in this sweep | | | | |\n";
      continue;
    }
    const int n = std::atoi(fewest->at("iterations").c_str());
    const double t = to_double(*fewest, "wall_s_per_sim_s");
    md << n << " | " << number(to_double(*fewest, measure)) << " | " << number(t) << " | "
       << number(t / t0) << " | " << kPaperIterations - n << " |\n";
  }
  md << "\n";
}

}  // namespace

std::string RunSpec::id() const {
  return scene + "." + name(solver) + "." + name(push) + "." + name(friction_model) +
         ".it" + std::to_string(iterations) + ".ss" + std::to_string(substeps) +
         (warm_start != 0.0 ? ".ws" + shortest_decimal(warm_start) : std::string());
}

RunSpec RunSpec::parse(const std::string& id) {
  const auto bad = [&id](const std::string& why) {
    const auto names = [](const char* parameter_name) {
      std::string list;
      for (const Choice& c : parameter(parameter_name).choices) {
        list += (list.empty() ? "" : "|") + std::string(c.name);
      }
      return list;
    };
    return UsageError("run id '" + id + "': " + why + "; expected scene." + names("solver") + "." +
                      names("push") + "." + names("friction_model") +
                      ".itN.ssM, optionally followed by .wsF, a warm start factor F in [0, 1]");
  };
  // The warm start factor, if any: ".wsF" right after the ".ssM" part (F may hold a dot).
  std::string rest = id;
  double warm_start = 0.0;
  const std::size_t ws = id.rfind(".ws");
  if (ws != std::string::npos) {
    const std::size_t ss = id.rfind(".ss", ws);
    const bool after_ss = ss != std::string::npos && ss + 3 < ws &&
                          id.find_first_not_of("0123456789", ss + 3) == ws;
    if (after_ss) {
      const std::string f = id.substr(ws + 3);
      const char* first = f.c_str();
      const char* last = first + f.size();
      const auto [end, ec] = std::from_chars(first, last, warm_start, std::chars_format::fixed);
      if (first == last || ec != std::errc() || end != last || !(warm_start >= 0.0) ||
          !(warm_start <= 1.0)) {
        throw bad("'ws" + f + "' is not a warm start factor in [0, 1]");
      }
      rest = id.substr(0, ws);
    }
  }
  // The last five parts are the settings; the scene is what comes before them (scene names may
  // hold a dot: pendulum_wave_dt_0.1).
  std::vector<std::string> parts;
  std::stringstream s(rest);
  for (std::string part; std::getline(s, part, '.');) parts.push_back(part);
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
  r.warm_start = warm_start;
  const scenes::Scene& scene = scene_of(r);
  check_steps("run " + id, scene.report_horizon_s(), std::get<double>(*overrides_of(r).find("dt")));
  return r;
}

bool is_paper_push(const Choice& push) { return push.in_paper; }

std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick) {
  const std::vector<int> iterations =
      quick ? std::vector<int>{1, 4, 16, 25, 64} : std::vector<int>{1, 2, 4, 8, 16, 25, 32, 64, 128, 256};
  const std::vector<int> substeps = quick ? std::vector<int>{4} : std::vector<int>{2, 4, 8, 16};
  std::vector<RunSpec> runs;
  for (const scenes::Scene* scene : scenes) {
    std::vector<FrictionModel> frictions = {FrictionModel::fixed};
    if (!quick && has_friction(*scene)) frictions.push_back(FrictionModel::coupled);
    for (const FrictionModel f : frictions) {
      for (const Choice& c : parameter("push").choices) {
        const auto p = static_cast<PushMode>(c.value);
        for (const SolverKind s : {SolverKind::pgs, SolverKind::jacobi}) {
          // The quick sweep runs Jacobi for the paper's push methods only (see the declaration).
          if (quick && s != SolverKind::pgs && !is_paper_push(c)) continue;
          for (const int it : iterations) runs.push_back({std::string(scene->name), s, p, f, it, 1});
          for (const int ss : substeps) runs.push_back({std::string(scene->name), s, p, f, 25, ss});
        }
        // Warm starting, PGS only (see the declaration); the quick sweep at the paper's push.
        if (quick && p != PushMode::baumgarte) continue;
        for (const double w : kReportWarmStarts) {
          if (quick) {
            for (const int it : kQuickWarmIterations) {
              runs.push_back({std::string(scene->name), SolverKind::pgs, p, f, it, 1, w});
            }
          } else {
            for (const int it : iterations) {
              runs.push_back({std::string(scene->name), SolverKind::pgs, p, f, it, 1, w});
            }
          }
        }
      }
    }
  }
  return runs;
}

Row execute_run(const RunSpec& spec, int repeats) {
  const scenes::Scene& scene = scene_of(spec);
  const double horizon = scene.report_horizon_s();
  const bool has_trajectory = !scene.report.has_reference_solution;
  const double t_traj = std::min(scene.report_trajectory_time_s(), horizon);
  scenes::Overrides o = overrides_of(spec);
  Row row;
  row["scene"] = spec.scene;
  // The columns of the settings are the table's JSON keys.
  row[std::string(parameter("solver").json_key)] = name(spec.solver);
  row[std::string(parameter("push").json_key)] = name(spec.push);
  row[std::string(parameter("friction_model").json_key)] = name(spec.friction_model);
  row[std::string(parameter("iterations").json_key)] = std::to_string(spec.iterations);
  row["substeps"] = std::to_string(spec.substeps);
  row[std::string(parameter("warm_start").json_key)] = shortest_decimal(spec.warm_start);
  row[std::string(parameter("dt").json_key)] = number(std::get<double>(*o.find("dt")));
  row["horizon_s"] = number(horizon);

  // The error run: residuals on, every step observed.
  o.set("measure_residual", true);
  const auto error_start = std::chrono::steady_clock::now();
  scenes::Run run = scenes::make_run(scene, o);
  double pen_max = 0.0, pen_sq = 0.0, rod_max = 0.0, rod_sq = 0.0;
  std::int64_t pen_n = 0, rod_n = 0;
  std::vector<Vec3> at_traj;
  std::optional<double> diverged_at;  // s
  // A run has diverged when its state is not finite or its penetration or rod error passes the
  // size of the largest movable body (bodies then pass through each other, rods stretch past any
  // shape in the scene): its numbers measure the blow-up, not the method's accuracy.
  const double size_bound = largest_body_size(run.world);
  while (run.world.time() + 0.5 * run.world.def().dt < horizon) {
    run.step();
    if (!sane_state(run.world)) {
      diverged_at = run.world.time();
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
      diverged_at = run.world.time();
      break;
    }
  }
  const double error_run_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - error_start).count();
  const bool diverged = diverged_at.has_value();
  // A run that diverged before the trajectory time steps on to it (the physics alone) while its
  // state stays finite: how far the blow-up has carried the bodies by then is its trajectory
  // error. A step that refuses the blown-up state (too many contacts) ends it without one.
  if (has_trajectory && diverged && at_traj.empty()) {
    try {
      while (sane_state(run.world) && run.world.time() + 0.5 * run.world.def().dt < t_traj) {
        run.world.step();
      }
      if (sane_state(run.world)) at_traj = positions(run.world);
    } catch (const std::exception&) {
      at_traj.clear();
    }
  }
  row["diverged"] = diverged ? "1" : "0";
  if (diverged) row["diverged_at_s"] = number(*diverged_at);
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
  }
  if (has_trajectory) {
    const Reference& ref = reference_of(spec);
    row["trajectory_time_s"] = number(t_traj);
    row["reference_check_m"] = number(ref.check_m);
    if (!at_traj.empty() && ref.positions) {
      row["trajectory_error_m"] = number(rms_distance(at_traj, *ref.positions));
    }
  }

  // Timing runs: the physics step alone, residuals off, metrics not fed; the median of repeats.
  // The error run above was the warm-up. A run whose error run took over 2 s is timed once. A
  // diverged run is timed up to the time it diverged: what the method cost until it failed.
  if (error_run_s > 2.0) repeats = std::min(repeats, 1);
  const double timed_until = diverged ? *diverged_at : horizon;
  o.set("measure_residual", false);
  std::vector<double> seconds;
  std::int64_t steps = 0;
  double simulated = 0.0;
  for (int r = 0; r < repeats; ++r) {
    scenes::Run timed = scenes::make_run(scene, o);
    const auto start = std::chrono::steady_clock::now();
    do {
      timed.world.step();
    } while (timed.world.time() + 0.5 * timed.world.def().dt < timed_until);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    steps = timed.world.counters().steps;
    simulated = timed.world.time();
  }
  if (!seconds.empty()) {
    std::sort(seconds.begin(), seconds.end());
    const double median = seconds[seconds.size() / 2];
    row["wall_s_per_sim_s"] = number(median / simulated);
    row["us_per_step"] = number(1e6 * median / static_cast<double>(std::max<std::int64_t>(steps, 1)));
    row["timing_repeats"] = std::to_string(seconds.size());
  }
  return row;
}

void write_csv(const fs::path& file, const std::vector<Row>& rows) {
  const std::vector<std::string> columns = ordered_columns(rows);
  std::ostringstream out;
  for (std::size_t c = 0; c < columns.size(); ++c) out << (c ? "," : "") << columns[c];
  out << "\n";
  for (const Row& r : rows) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const auto it = r.find(columns[c]);
      out << (c ? "," : "") << (it == r.end() ? "" : it->second);
    }
    out << "\n";
  }
  write_text_atomic(file, out.str());
}

std::vector<Row> read_rows(const std::vector<fs::path>& dirs) {
  std::vector<Row> rows;
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
      std::ifstream in(file);
      std::string line;
      std::getline(in, line);
      std::vector<std::string> header;
      std::stringstream hs(line);
      for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
      if (header.empty() || header[0] != "scene") {
        throw UsageError("--merge: " + file.string() +
                         " is not a cps report CSV (its header does not start with 'scene')");
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

std::vector<std::string> missing_runs(const std::vector<Row>& rows, std::size_t& planned) {
  std::set<std::pair<std::string, bool>> sweeps;
  std::set<std::string> present;
  for (const Row& r : rows) {
    const auto sweep = r.find("sweep");
    const auto quick = r.find("quick");
    sweeps.emplace(sweep != r.end() ? sweep->second : r.at("scene"),
                   quick != r.end() && quick->second == "1");
    present.insert(id_of(r));
  }
  std::vector<std::string> missing;
  std::set<std::string> seen;
  for (const auto& [sweep, quick] : sweeps) {
    std::vector<const scenes::Scene*> scenes;
    try {
      scenes = select_scenes(sweep);
    } catch (const std::exception&) {
      // A sweep this build does not know (a CSV of another build): its plan is unknown.
    }
    for (const RunSpec& spec : plan_runs(scenes, quick)) {
      const std::string id = spec.id();
      if (seen.insert(id).second && !present.count(id)) missing.push_back(id);
    }
  }
  planned = seen.size();
  return missing;
}

void write_report(const fs::path& dir, const std::vector<Row>& rows,
                  const std::vector<std::string>& missing, std::size_t planned) {
  std::map<std::string, std::vector<const Row*>> by_scene;
  std::vector<std::string> order;
  for (const Row& r : rows) {
    if (!by_scene.count(r.at("scene"))) order.push_back(r.at("scene"));
    by_scene[r.at("scene")].push_back(&r);
  }
  const auto cell = [](const Row& r, const std::string& c) {
    const auto it = r.find(c);
    return it == r.end() ? std::string() : it->second;
  };
  std::ostringstream md;
  std::string title_note;
  md << "# Error against run time\n\n";
  if (!missing.empty()) {
    title_note = " (INCOMPLETE: " + std::to_string(missing.size()) + " of " +
                 std::to_string(planned) + " runs missing)";
    md << "**INCOMPLETE: " << missing.size() << " of the " << planned
       << " planned runs are missing.** Every table and diagram below lacks them; the "
          "headline compares only the runs present. Missing:";
    for (std::size_t i = 0; i < missing.size() && i < 20; ++i) md << (i ? ", " : " ") << "`" << missing[i] << "`";
    if (missing.size() > 20) md << " and " << missing.size() - 20 << " more";
    md << ".\n\n";
  }
  int repeats_min = 1 << 30, repeats_max = 0;
  for (const Row& r : rows) {
    const int n = std::atoi(cell(r, "timing_repeats").c_str());
    if (n > 0) repeats_min = std::min(repeats_min, n), repeats_max = std::max(repeats_max, n);
  }
  md << "Made by `cps report` from " << rows.size() << " runs. What the numbers are:\n\n"
     << "- **Time (s/s)**: physics wall time per simulated second, the median of ";
  if (repeats_max > 0 && repeats_min == repeats_max) {
    md << repeats_max;
  } else if (repeats_max > 0) {
    md << repeats_min << " to " << repeats_max;
  } else {
    md << "the";
  }
  md << " timing runs of the step alone (no metrics, no residual; column timing_repeats) after "
        "the error run as warm-up; a run whose error run took over 2 s is timed once. A "
        "diverged run is timed until it diverged.\n"
     << "- **Diverged**: the state stopped being finite, or a penetration or rod error passed "
        "the size of the largest movable body (the time: diverged_at_s). Its other measures "
        "stop there and are left out of the headline. In the diagrams it is a red x on the top "
        "edge, at its time until it diverged.\n"
     << "- **Trajectory error (m)**: RMS distance of the movable bodies from a reference run "
        "(PGS, " << kReferenceIterations << " iterations, " << kReferenceSubsteps
     << " substeps, the run's push and friction model) at the scene's trajectory time, given "
        "with its reason under each scene. A run that diverged before that time steps on to it "
        "(the physics alone) while its state stays finite. **The reference's own error** (reference_check_m) is its "
        "distance from the same run at " << kReferenceSubsteps / 2
     << " substeps: halving dt halves a first-order method's error, so that distance is about "
        "the reference's error. Trajectory errors under it are not resolved.\n"
     << "- **LCP residual (N)**: the natural-map residual |lambda - clamp(lambda - (A lambda - "
        "b) / A_jj, c_min, c_max)| over every row of every solve.\n"
     << "- **Substeps**: steps per 1/60 s frame (dt = 1 / (60 substeps) s); the iteration sweep "
        "runs at 1 substep, the substep sweep at 25 iterations.\n"
     << "- **Warm start** (column warm_start, dimensionless): each PGS row's lambda starts from "
        "this factor times its lambda of the previous step where its contact or rod persists "
        "(Sec. 6.2.3); 0 is the paper's cold start from 0. Every run above starts cold but the "
        "warm-started PGS iteration lines (1 substep), drawn in the same panels in their own "
        "colours; each scene's table \"Warm starting\" gives the fewest iterations with which "
        "PGS reaches the paper's error cold and warm, and the iterations saved.\n"
     << "- **Round-off floors** (diagrams only; tables and CSVs keep every value): " << kFloorNotes
     << "\n\n"
     << "## Headline: the paper's settings and the cheapest run with at most half their error\n\n"
     << "The cheapest run (least time) whose value of the scene's measure is at most half the "
        "value at the paper's settings, among every run of the scene (every solver, push and "
        "friction model), diverged runs left out. For the trajectory error a run counts only "
        "if half the paper's value is above its reference's own error.\n\n"
     << "| scene | measure | at the paper's settings (PGS, Baumgarte, fixed friction, 25 it, 60 Hz) "
        "| its time (s/s) | cheapest run with at most half of it | its time (s/s) | time ratio |\n"
        "|---|---|---|---|---|---|---|\n";
  for (const std::string& scene : order) {
    const std::string measure = primary_measure(scene);
    const Row* base = nullptr;
    for (const Row* r : by_scene[scene]) {
      if (is_paper_setting(*r)) base = r;
    }
    md << "| " << scene << " | " << label_of(measure) << " | ";
    if (!base || base->at("diverged") == "1" || std::isnan(to_double(*base, measure))) {
      md << (base ? "diverged or not measured" : "not in this sweep") << " | | | | |\n";
      continue;
    }
    const double e0 = to_double(*base, measure);
    const double t0 = to_double(*base, "wall_s_per_sim_s");
    const bool trajectory = measure == "trajectory_error_m";
    const Row* best = nullptr;
    for (const Row* r : by_scene[scene]) {
      if (r->at("diverged") == "1") continue;
      const double e = to_double(*r, measure);
      const double t = to_double(*r, "wall_s_per_sim_s");
      if (trajectory && !(0.5 * e0 > to_double(*r, "reference_check_m"))) continue;
      if (e <= 0.5 * e0 && std::isfinite(t) && (!best || t < to_double(*best, "wall_s_per_sim_s"))) best = r;
    }
    md << number(e0);
    if (trajectory && e0 < to_double(*base, "reference_check_m")) {
      md << " (under its reference's own error, " << cell(*base, "reference_check_m") << ")";
    }
    md << " | " << number(t0) << " | ";
    if (best) {
      const double t1 = to_double(*best, "wall_s_per_sim_s");
      md << best->at("solver") << ", " << best->at("push") << ", " << best->at("friction_model")
         << ", " << best->at("iterations") << " it, " << best->at("substeps")
         << (best->at("substeps") == "1" ? " substep" : " substeps")
         << (warm_of(*best) != 0.0 ? ", warm start " + shortest_decimal(warm_of(*best)) : std::string())
         << ": " << number(to_double(*best, measure)) << " | " << number(t1) << " | "
         << number(t1 / t0) << " |\n";
    } else {
      md << "none in this sweep | | |\n";
    }
  }
  md << "\n";
  for (const std::string& scene : order) {
    std::vector<Row> scene_rows;
    for (const Row* r : by_scene[scene]) scene_rows.push_back(*r);
    write_csv(dir / (file_stem(scene) + ".csv"), scene_rows);
    md << "## " << scene << "\n\n";
    if (const scenes::Scene* s = scenes::find_scene(scene)) {
      md << "- **Horizon** " << number(s->report_horizon_s()) << " s: " << s->report.horizon_reason
         << ".\n- **Trajectory time** ";
      if (s->report.has_reference_solution) {
        md << s->report.trajectory_reason << ".";
      } else {
        md << number(std::min(s->report_trajectory_time_s(), s->report_horizon_s())) << " s: "
           << s->report.trajectory_reason << ".";
      }
      md << "\n";
    }
    std::map<std::string, std::string> checks;  // push, friction -> reference's own error
    for (const Row* r : by_scene[scene]) {
      if (!cell(*r, "reference_check_m").empty()) {
        checks[r->at("push") + ", " + r->at("friction_model") + " friction"] = cell(*r, "reference_check_m");
      }
    }
    if (!checks.empty()) {
      md << "- **The reference's own error** at the trajectory time (m):";
      bool first = true;
      for (const auto& [variant, value] : checks) {
        md << (first ? " " : "; ") << variant << ": " << value;
        first = false;
      }
      md << ".\n";
    }
    md << "\nAll runs: [" << file_stem(scene) << ".csv](" << file_stem(scene) << ".csv).\n\n";
    write_warm_table(md, scene, by_scene[scene]);
    for (const Measure& m : kMeasures) {
      if (plot_measure(dir, scene, m, by_scene[scene], title_note)) {
        md << "![" << scene << " " << m.column << "](" << file_stem(scene) << "_" << m.column << ".png)\n\n";
      }
    }
    const std::string measure = primary_measure(scene);
    md << "| solver | push | friction | iterations | substeps | warm start | time (s/s) | "
       << label_of(measure)
       << " | residual RMS (N) | penetration max (m) | rod error max (m) | diverged at (s) |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row* r : by_scene[scene]) {
      md << "| " << cell(*r, "solver") << " | " << cell(*r, "push") << " | "
         << cell(*r, "friction_model") << " | " << cell(*r, "iterations") << " | "
         << cell(*r, "substeps") << " | " << shortest_decimal(warm_of(*r)) << " | "
         << cell(*r, "wall_s_per_sim_s") << " | "
         << cell(*r, measure) << " | " << cell(*r, "residual_rms_N") << " | "
         << cell(*r, "penetration_max_m") << " | " << cell(*r, "rod_error_max_m") << " | "
         << (cell(*r, "diverged") == "1" ? cell(*r, "diverged_at_s") : "no") << " |\n";
    }
    md << "\n";
  }
  const std::vector<Row> pairs = mass_ratio_rows();
  write_csv(dir / "mass_ratio.csv", pairs);
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
     << " m). The last column lists the iteration counts of 1, 2, 4, ..., 256 with which the "
        "same run holds with under 1 cm of overlap (holding need not grow with the count). All "
        "in [mass_ratio.csv](mass_ratio.csv).\n\n"
     << "| mass ratio | solver | push | held at 25 it | heavy cube height (m) | light cube off "
        "the heavy one's axis (m) | deepest overlap (m) | iterations that hold, overlap under "
        "1 cm |\n|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : pairs) {
    md << "| " << cell(r, "mass_ratio") << " | " << cell(r, "solver") << " | " << cell(r, "push")
       << " | " << (cell(r, "held") == "1" ? "yes" : "no") << " | " << cell(r, "heavy_height_m")
       << " | " << cell(r, "light_offset_m") << " | " << cell(r, "overlap_m") << " | "
       << (cell(r, "iterations_holding").empty() ? std::string("none")
                                                  : cell(r, "iterations_holding")) << " |\n";
  }
  md << "\n";
  write_text_atomic(dir / "report.md", md.str());
}

std::vector<std::string> report_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files = {"report.md", "mass_ratio.csv"};
  for (const std::string& scene : scenes) {
    files.push_back(file_stem(scene) + ".csv");
    for (const Measure& m : kMeasures) {
      for (const char* ext : {".png", ".svg", ".pdf"}) files.push_back(file_stem(scene) + "_" + m.column + ext);
    }
  }
  return files;
}

std::vector<std::string> plot_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files;
  for (const std::string& scene : scenes) {
    for (const Measure& m : kMeasures) {
      for (const char* ext : {".dat", ".gp"}) files.push_back(file_stem(scene) + "_" + m.column + ext);
    }
  }
  return files;
}

namespace {

// Timing runs per run (the median is taken), in the quick sweep as in the full one.
constexpr int kTimingRepeats = 3;

// The options of `cps report`.
struct ReportOptions {
  std::string scene = "all";
  std::string out = "out/report";
  bool quick = false;
  bool list = false;
  std::vector<std::string> merge;
  std::string run;
  bool force = false;
};

// The absolute path of this executable, for commands that must run anywhere.
std::string self_path() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "cps";
  path[n] = '\0';
  return path;
}

// The report's two folders (OUT and OUT/plots, both shared: see output.h), checked for the
// report of `scenes` before any work; write() then begins them, calls `body` and ends them, so
// that each folder's run.json lists what was written.
struct ReportOutput {
  OutputPlan main;
  OutputPlan plots;
  nlohmann::json info;

  ReportOutput(const fs::path& out, const std::vector<std::string>& scenes, bool force,
               nlohmann::json run)
      : main(plan_output(out, report_files(scenes), force, FolderUse::shared)),
        plots(plan_output(out / "plots", plot_files(scenes), force, FolderUse::shared)),
        info(std::move(run)) {}

  template <class Body>
  void write(Body&& body) {
    begin_output(main, info);
    begin_output(plots, info);
    body();
    end_output(plots, info);
    end_output(main, info);
  }
};

std::vector<std::string> scene_names(const std::vector<const scenes::Scene*>& scenes) {
  std::vector<std::string> names;
  for (const scenes::Scene* s : scenes) names.emplace_back(s->name);
  return names;
}

// The scene argument that runs `cps report push` instead of a sweep.
constexpr const char* kPushReport = "push";

// select_scenes for the report's scene argument: its error also names 'push'.
std::vector<const scenes::Scene*> report_scenes(const std::string& name) {
  try {
    return select_scenes(name);
  } catch (const UsageError& e) {
    throw UsageError(std::string(e.what()) + "; cps report also takes '" + kPushReport +
                     "' (every push method side by side: cps report push [--quick] [--out DIR])");
  }
}

int run_report(const ReportOptions& o, int argc, char** argv) {
  nlohmann::json merged = nlohmann::json::array();
  for (const std::string& m : o.merge) merged.push_back(m);
  const nlohmann::json info = run_info(
      "report", argc, argv,
      {{"scene", o.scene}, {"quick", o.quick}, {"repeats", kTimingRepeats}, {"merge", merged},
       {"run", o.run.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.run)}});
  if (o.scene == kPushReport) {
    const char* sweep_only = !o.run.empty() ? "--run" : !o.merge.empty() ? "--merge"
                             : o.list        ? "--list-runs" : nullptr;
    if (sweep_only) {
      throw UsageError(std::string("report push: ") + sweep_only +
                       " applies to the sweeps (a scene, 'all' or 'stress'), not to the push "
                       "methods side by side; cps report push takes --out, --quick and --force");
    }
    return run_push_report(o.out, o.quick, o.force, info);
  }
  const int repeats = kTimingRepeats;
  // The sweep a run belongs to, recorded in its row so that --merge can tell what is missing.
  const auto mark_sweep = [&o](Row& row) {
    row["sweep"] = o.scene;
    row["quick"] = o.quick ? "1" : "0";
  };
  if (!o.merge.empty()) {
    std::vector<fs::path> dirs(o.merge.begin(), o.merge.end());
    const std::vector<Row> rows = read_rows(dirs);
    if (rows.empty()) throw UsageError("--merge: no report CSV found below the given folders");
    std::size_t planned = 0;
    const std::vector<std::string> missing = missing_runs(rows, planned);
    std::vector<std::string> scenes;
    for (const Row& r : rows) {
      if (std::find(scenes.begin(), scenes.end(), r.at("scene")) == scenes.end()) {
        scenes.push_back(r.at("scene"));
      }
    }
    ReportOutput output(o.out, scenes, o.force, info);
    output.write([&] { write_report(o.out, rows, missing, planned); });
    if (!missing.empty()) {
      std::string named;
      for (std::size_t i = 0; i < missing.size() && i < 5; ++i) named += (i ? ", " : "") + missing[i];
      if (missing.size() > 5) named += " and " + std::to_string(missing.size() - 5) + " more";
      std::fprintf(stderr,
                   "report --merge: %zu of the %zu planned runs are missing: %s. %s/report.md "
                   "is marked INCOMPLETE.\n",
                   missing.size(), planned, named.c_str(), o.out.c_str());
      return 1;
    }
    std::printf("merged %zu runs into %s/report.md\n", rows.size(), o.out.c_str());
    return 0;
  }
  if (!o.run.empty()) {
    const RunSpec spec = RunSpec::parse(o.run);
    report_scenes(o.scene);  // the sweep it belongs to must be one
    // The run id with the scene part as file_stem: a scene file path keeps its folders out.
    const std::string file = file_stem(spec.scene) + spec.id().substr(spec.scene.size()) + ".csv";
    const OutputPlan plan = plan_output(o.out, {file}, o.force, FolderUse::shared);
    Row row = execute_run(spec, repeats);
    mark_sweep(row);
    begin_output(plan, info);
    write_csv(fs::path(o.out) / file, {row});
    end_output(plan, info);
    return 0;
  }
  const std::vector<RunSpec> runs = plan_runs(report_scenes(o.scene), o.quick);
  if (o.list) {
    const std::string exe = self_path();
    for (const RunSpec& r : runs) {
      std::printf("'%s' report '%s' --run %s --out '%s/runs'%s\n", exe.c_str(), o.scene.c_str(),
                  r.id().c_str(), o.out.c_str(), o.quick ? " --quick" : "");
    }
    std::printf("# when all have finished: '%s' report --merge '%s/runs' --out '%s'\n",
                exe.c_str(), o.out.c_str(), o.out.c_str());
    return 0;
  }
  ReportOutput output(o.out, scene_names(report_scenes(o.scene)), o.force, info);
  std::vector<Row> rows;
  Progress progress("report " + o.scene, static_cast<long long>(runs.size()), "runs");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    rows.push_back(execute_run(runs[i], repeats));
    mark_sweep(rows.back());
    progress.update(static_cast<long long>(i + 1));
  }
  progress.finish();
  output.write([&] { write_report(o.out, rows, {}, rows.size()); });
  std::printf("%zu runs: %s/report.md\n", rows.size(), o.out.c_str());
  return 0;
}

}  // namespace

Command add_report(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* sub = app.add_subcommand(
      "report", "error against run time: sweep solver settings, write CSV, plots, report.md; "
                "'cps report push': every push method side by side (push.csv, push.md, plots)");
  sub->add_option("scene", o->scene,
                  "scene name, the path of a scene file (.json), 'all' (the paper's) or "
                  "'stress'; with --run, the sweep the run belongs to; 'push': instead of a "
                  "sweep, every push method (the choices of --push) on the same cases: the "
                  "intersecting stack and sphere_in_box (overlaps resolved, energy injected, "
                  "final heights), the stack over 600 s (60 s with --quick), the mass ratios "
                  "that hold, the pendulums' rod and phase errors and the cost per step, into "
                  "push.csv, push.md, push_overlap.png and push_speed.png in --out")
      ->capture_default_str();
  add_seed_option(*sub, o->scene);
  sub->add_option("--out", o->out, "output folder")->capture_default_str()->check(kNotEmpty);
  const std::size_t quick_runs = plan_runs(select_scenes("all"), true).size();
  sub->add_flag("--quick", o->quick,
                "a reduced sweep: iterations 1, 4, 16, 25, 64 and 4 substeps, fixed friction "
                "only, Jacobi for the paper's push methods only, and warm-started PGS (warm "
                "start 0.8 and 1) at iterations 1, 4, 16, 25 with Baumgarte push; each run "
                "timed by the median of 3 timing runs as in the full sweep (the paper's five "
                "scenes: " + std::to_string(quick_runs) + " runs; with the two push methods "
                "baumgarte and split, 160 runs measured 63 s on 2 cores shared with other "
                "jobs); with 'push': the stack over 60 s and the pendulum wave over 10 s");
  CLI::Option* list = sub->add_flag("--list-runs", o->list,
                "print one self-contained command per run, to spread the sweep over machines");
  CLI::Option* merge = sub->add_option("--merge", o->merge,
                  "combine the CSV files below these folders into one report in --out; if runs "
                  "of the sweeps they belong to are missing, it names them on stderr, writes the "
                  "report marked INCOMPLETE at the top (and in every diagram's title) and exits "
                  "with 1")
      ->check(kNotEmpty);
  CLI::Option* run = sub->add_option("--run", o->run,
                  "execute one run by its id (see --list-runs); the scene argument and --quick "
                  "name the sweep it belongs to, recorded in its CSV for --merge")
      ->check(kNotEmpty);
  run->excludes(merge)->excludes(list);
  merge->excludes(list);
  sub->add_flag("--force", o->force,
                "let the report replace files in --out that have the names of its own outputs "
                "but that no earlier cps run wrote there (other files are never touched)");
  return {sub, [o, argc, argv] { return run_report(*o, argc, argv); }};
}

}  // namespace cps::cli
