#include "report/diagrams.h"

#include "report/gnuplot.h"
#include "report/headline.h"
#include "output/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

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
// the diagrams' panels); names the table does not have (a CSV of another build) after them.
int push_rank(const std::string& value) {
  int i = 0;
  for (const Choice& c : parameter("push").choices) {
    if (value == c.name) return i;
    ++i;
  }
  return i;
}

// One point of a diagram: physics time (s/s), the value drawn, its label, and the first and
// third quartiles of the time (s/s; the error bar, x itself where the run has none).
struct PlotPoint {
  double x = 0.0;
  double y = 0.0;
  std::string label;
  double x_lo = 0.0;
  double x_hi = 0.0;
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
  // Trajectory errors under their reference's own error (under_reference_error): drawn where
  // they are, ringed with their own mark.
  std::vector<PlotPoint> unresolved;
  // Runs that never recovered within the horizon (ranked_value infinite): drawn at the top
  // edge, under the diverged runs' marks' row.
  std::vector<PlotPoint> never;
  // Labels, placed by place_labels (x, y: the label's centre): the first and last point of the
  // iteration line, the last of the substep line, every diverged run.
  std::vector<PlotPoint> labels_it;
  std::vector<PlotPoint> labels_ss;
  std::vector<PlotPoint> labels_div;
  std::vector<PlotPoint> labels_never;
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
  bool any_unresolved = false;
  bool any_never = false;
  std::string dt1 = "?";  // the dt of the runs at 1 substep (dt_text)
  std::vector<double> warm_factors;  // the warm start factors (> 0) of any run, ascending
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;  // y_hi: the top edge
};

// The range of the values drawn so far: the least value before clamping to the floor, the
// largest value drawn, the times; any_value once a run that finished has a value.
struct Extent {
  double raw_min = kInfinity, y_max = 0.0, x_min = kInfinity, x_max = 0.0;
  bool any_value = false;
  void add_x(double x) {
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
  }
};

// The runs of each panel, in the panels' order: friction model (fixed, coupled), push (the
// table's order), solver (pgs, jacobi).
std::vector<std::vector<const RunResult*>> panel_runs(const std::vector<const RunResult*>& runs) {
  const auto key_of = [](const RunResult& r) {
    return std::make_tuple(rank_of(r.friction_model, {"fixed", "coupled"}), push_rank(r.push),
                           rank_of(r.solver, {"pgs", "jacobi"}), r.variant());
  };
  std::map<std::tuple<int, int, int, std::string>, std::vector<const RunResult*>> by_panel;
  for (const RunResult* r : runs) by_panel[key_of(*r)].push_back(r);
  std::vector<std::vector<const RunResult*>> panels;
  for (auto& [key, panel] : by_panel) panels.push_back(std::move(panel));
  return panels;
}

// The warm start factors (> 0) of any run, ascending.
std::vector<double> warm_factors_of(const std::vector<const RunResult*>& runs) {
  std::vector<double> factors;
  for (const RunResult* r : runs) {
    const double w = r->warm_start;
    if (w != 0.0 && std::find(factors.begin(), factors.end(), w) == factors.end()) {
      factors.push_back(w);
    }
  }
  std::sort(factors.begin(), factors.end());
  return factors;
}

// The points of a line by count, in the order of the counts.
std::vector<PlotPoint> by_count(std::vector<std::pair<int, PlotPoint>> line) {
  std::sort(line.begin(), line.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<PlotPoint> points;
  for (const auto& [n, point] : line) points.push_back(point);
  return points;
}

// The panel of one solver, push and friction model: its runs' points on the lines they belong
// to, the clamped and diverged marks, the labels to place and, for the trajectory error, the
// reference's own error. Widens `e` by what it draws and sets d's flags.
Panel make_panel(const Measure& m, const std::vector<const RunResult*>& runs, Diagram& d, Extent& e) {
  Panel p;
  const RunResult& first = *runs.front();
  const PushReads reads = first.reads();
  p.title = (reads.solver ? first.solver + ", " : std::string()) + first.push + " push" +
            (reads.friction_model ? ", " + first.friction_model + " friction" : std::string());
  std::vector<const RunResult*> sorted = runs;
  std::sort(sorted.begin(), sorted.end(), [](const RunResult* a, const RunResult* b) {
    return std::make_pair(a->substeps, a->iterations) < std::make_pair(b->substeps, b->iterations);
  });
  std::vector<std::pair<int, PlotPoint>> it_line, ss_line;
  std::vector<std::vector<std::pair<int, PlotPoint>>> warm_lines(d.warm_factors.size());
  for (const RunResult* r : sorted) {
    const double t = r->cpu_s_per_sim_s.value_or(std::nan(""));
    if (!(t > 0.0)) continue;
    // The error bar: the quartiles of the time, where they are positive.
    const double q1 = r->cpu_s_per_sim_s_q1.value_or(t), q3 = r->cpu_s_per_sim_s_q3.value_or(t);
    const double t_lo = q1 > 0.0 ? std::min(q1, t) : t, t_hi = std::max(q3, t);
    const int it = r->iterations, ss = r->substeps;
    const double w = r->warm_start;
    const std::string label = (ss == 1 ? std::to_string(it) + " it" : std::to_string(ss) + " ss") +
                              (w != 0.0 ? ", ws " + shortest_decimal(w) : std::string());
    if (r->diverged) {
      p.diverged.push_back({t, 0.0, label, t_lo, t_hi});
      d.any_diverged = true;
      e.add_x(t_lo);
      e.add_x(t_hi);
      continue;
    }
    if (std::isinf(ranked_value(*r, m.column))) {
      p.never.push_back({t, 0.0, label, t_lo, t_hi});
      // The paper's run ringed on the top edge too (y set there with the never marks').
      if (ss == 1 && it == kPaperIterations && w == 0.0) p.paper.push_back({t, 0.0, label, t, t});
      d.any_never = true;
      e.add_x(t_lo);
      e.add_x(t_hi);
      continue;
    }
    const double value = r->value(m.column);
    if (std::isnan(value)) continue;
    e.any_value = true;
    e.raw_min = std::min(e.raw_min, value);
    const PlotPoint point{t, std::max(value, d.floor), label, t_lo, t_hi};
    if (value < d.floor) {
      p.clamped.push_back(point);
      d.any_clamped = true;
    }
    if (std::string(m.column) == "trajectory_error_m" && r->under_reference_error.value_or(false)) {
      p.unresolved.push_back(point);
      d.any_unresolved = true;
    }
    e.y_max = std::max(e.y_max, point.y);
    e.add_x(t_lo);
    e.add_x(t_hi);
    if (w != 0.0) {
      // Warm runs: the iteration line of their factor only (the sweep has no warm substeps).
      const auto k = std::find(d.warm_factors.begin(), d.warm_factors.end(), w);
      if (ss == 1) warm_lines[static_cast<std::size_t>(k - d.warm_factors.begin())].emplace_back(it, point);
      continue;
    }
    if (ss == 1) it_line.emplace_back(it, point);
    if (it == kPaperIterations) ss_line.emplace_back(ss, point);
    if (ss == 1 && it == kPaperIterations) p.paper.push_back(point);
  }
  for (auto& line : warm_lines) p.warm.push_back(by_count(std::move(line)));
  p.iterations = by_count(std::move(it_line));
  p.substeps = by_count(std::move(ss_line));
  if (!p.iterations.empty()) p.labels_it.push_back(p.iterations.front());
  if (p.iterations.size() > 1) p.labels_it.push_back(p.iterations.back());
  if (p.substeps.size() > 1) p.labels_ss.push_back(p.substeps.back());
  // A reference whose own error is under the floor (the same positions to round-off) has no
  // line: it would lie on the floor's.
  const double ref = first.reference_error_m.value_or(std::nan(""));
  if (std::string(m.column) == "trajectory_error_m" && ref >= d.floor) {
    p.reference = ref;
    d.any_reference = true;
    e.y_max = std::max(e.y_max, p.reference);
  }
  return p;
}

// The axes of a diagram from the extent of its values: a third of a decade of room around the
// lines (and the floor's label), a decade above for the diverged marks, which sit on the top
// edge; the floor drawn when a value comes within two decades of it (otherwise it would only
// stretch the axis).
void set_axes(Diagram& d, const Extent& e) {
  d.show_floor = e.raw_min < 100.0 * d.floor;
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
  if (d.show_floor) y_min = std::min(y_min, d.floor / 3.0);
  d.y_lo = y_min / 3.0;
  d.y_hi = std::max(e.y_max, y_min) * 3.0;
  if (d.any_diverged || d.any_never) d.y_hi *= 10.0;
  for (Panel& p : d.panels) {
    for (PlotPoint& q : p.diverged) q.y = d.y_hi;
    for (PlotPoint& q : p.never) q.y = d.y_hi;
    for (PlotPoint& q : p.paper) q.y = q.y > 0.0 ? q.y : d.y_hi;
  }
  d.x_lo = e.x_min / 1.5;
  d.x_hi = e.x_max * 1.5;
}

// Sizes in a panel's frame, as fractions of its width (u) and height (v): a panel's frame is
// about 480 x 240 pixels, a label character (font size 8) about 5 x 11 pixels.
constexpr double kCharU = 5.0 / 480.0, kLabelV = 11.0 / 240.0;
constexpr double kPointU = 6.0 / 480.0, kPointV = 6.0 / 240.0;  // half a point mark, with a gap

// A rectangle in a panel's frame (u, v in [0, 1] inside it).
struct Box {
  double u0, u1, v0, v1;
};

// The frame coordinates of a panel's data coordinates (log-log axes) and back.
struct Frame {
  double x_lo, y_lo, lu, lv;
  explicit Frame(const Diagram& d)
      : x_lo(d.x_lo), y_lo(d.y_lo), lu(std::log(d.x_hi / d.x_lo)), lv(std::log(d.y_hi / d.y_lo)) {}
  double u(double x) const { return std::log(x / x_lo) / lu; }
  double v(double y) const { return std::log(y / y_lo) / lv; }
  PlotPoint centre(const Box& b, const std::string& label) const {
    const double x = x_lo * std::exp(0.5 * (b.u0 + b.u1) * lu);
    return {x, y_lo * std::exp(0.5 * (b.v0 + b.v1) * lv), label, x, x};
  }
};

// What a panel's labels must not cover: its point marks (the paper's ring larger), and the
// floor's and the reference's lines as thin boxes across the frame.
std::vector<Box> taken_boxes(const Panel& p, const Diagram& d, const Frame& f) {
  std::vector<Box> taken;
  const auto mark = [&](const PlotPoint& q, double grow) {
    const double u = f.u(q.x), v = f.v(q.y);
    taken.push_back({u - grow * kPointU, u + grow * kPointU, v - grow * kPointV, v + grow * kPointV});
  };
  for (const auto* list : {&p.iterations, &p.substeps, &p.clamped, &p.diverged, &p.paper,
                           &p.unresolved, &p.never}) {
    for (const PlotPoint& q : *list) mark(q, list == &p.paper || list == &p.unresolved ? 1.7 : 1.0);
  }
  for (const auto& line : p.warm) {
    for (const PlotPoint& q : line) mark(q, 1.0);
  }
  for (const double y : {d.show_floor ? d.floor : 0.0, p.reference}) {
    if (y > 0.0) taken.push_back({0.0, 1.0, f.v(y) - 0.01, f.v(y) + 0.01});
  }
  return taken;
}

// The place of one label by its point q: the first free place of eight around it (above, below,
// right, left, then the corners; under_only: only under it, further down if need be), or the
// least crowded one, where outside the frame counts as crowded as a full overlap. The place is
// added to `taken`.
PlotPoint place_label(const PlotPoint& q, bool under_only, const Frame& f, std::vector<Box>& taken) {
  const auto overlap = [](const Box& a, const Box& b) {
    const double du = std::min(a.u1, b.u1) - std::max(a.u0, b.u0);
    const double dv = std::min(a.v1, b.v1) - std::max(a.v0, b.v0);
    return du > 0.0 && dv > 0.0 ? du * dv : 0.0;
  };
  const double u = f.u(q.x), v = f.v(q.y);
  const double hw = 0.5 * kCharU * static_cast<double>(q.label.size()), hh = 0.5 * kLabelV;
  const double du = kPointU + hw, dv = kPointV + hh;
  std::vector<std::pair<double, double>> offsets;
  if (under_only) {
    for (int k = 1; k <= 4; ++k) offsets.emplace_back(0.0, -dv - (k - 1) * 2.0 * hh);
  } else {
    offsets = {{0.0, dv}, {0.0, -dv}, {du, 0.0}, {-du, 0.0}, {du, dv}, {-du, dv}, {du, -dv}, {-du, -dv}};
  }
  Box best{};
  double best_cost = kInfinity;
  for (const auto& [ou, ov] : offsets) {
    const Box b{u + ou - hw, u + ou + hw, v + ov - hh, v + ov + hh};
    double cost = 0.0;
    for (const Box& t : taken) cost += overlap(b, t);
    if (b.u0 < 0.0 || b.u1 > 1.0 || b.v0 < 0.0 || b.v1 > 1.0) cost += 4.0 * hw * hh;
    if (cost < best_cost) best_cost = cost, best = b;
    if (cost == 0.0) break;
  }
  taken.push_back(best);
  return f.centre(best, q.label);
}

// Places a panel's labels so that no label overlaps another label, a point mark or the frame's
// edge: the diverged runs' labels first, then those of the runs that never recovered (left to
// right, under their marks), then the iteration and substep lines'. The labels' positions are in data coordinates.
void place_labels(Panel& p, const Diagram& d) {
  const Frame f(d);
  std::vector<Box> taken = taken_boxes(p, d, f);
  for (const auto& [marks, labels] :
       {std::pair{&p.diverged, &p.labels_div}, std::pair{&p.never, &p.labels_never}}) {
    std::vector<PlotPoint> sorted = *marks;
    std::sort(sorted.begin(), sorted.end(),
              [](const PlotPoint& a, const PlotPoint& b) { return a.x < b.x; });
    for (const PlotPoint& q : sorted) labels->push_back(place_label(q, true, f, taken));
  }
  std::vector<PlotPoint> it = std::move(p.labels_it), ss = std::move(p.labels_ss);
  p.labels_it.clear();
  p.labels_ss.clear();
  for (const PlotPoint& q : it) p.labels_it.push_back(place_label(q, false, f, taken));
  for (const PlotPoint& q : ss) p.labels_ss.push_back(place_label(q, false, f, taken));
}

// The diagram of measure m over the runs of one scene, or nullopt if no run that finished has a
// value of it (floor: the measure's round-off floor in its unit).
std::optional<Diagram> make_diagram(const Measure& m, double floor,
                                    const std::vector<const RunResult*>& runs) {
  Diagram d;
  d.floor = floor;
  d.warm_factors = warm_factors_of(runs);
  for (const RunResult* r : runs) {
    if (r->substeps == 1 && r->dt_s) d.dt1 = dt_text(*r);
  }
  Extent e;
  for (const std::vector<const RunResult*>& panel : panel_runs(runs)) {
    d.panels.push_back(make_panel(m, panel, d, e));
  }
  if (!e.any_value) return std::nullopt;
  set_axes(d, e);
  for (Panel& p : d.panels) place_labels(p, d);
  return d;
}

// The diagram's data: one gnuplot index block per non-empty list, in the order plot_script
// reads them; per line x, y, the error bar's ends x_lo and x_hi, and a "label" (for the label
// lists, x and y are where the label's centre goes).
std::string plot_data(const Diagram& d) {
  std::ostringstream out;
  for (const Panel& p : d.panels) {
    std::vector<const std::vector<PlotPoint>*> lists = {&p.iterations};
    for (const auto& line : p.warm) lists.push_back(&line);
    for (const auto* list : {&p.substeps, &p.paper, &p.clamped, &p.diverged, &p.unresolved,
                             &p.never, &p.labels_it, &p.labels_ss, &p.labels_div,
                             &p.labels_never}) {
      lists.push_back(list);
    }
    for (const auto* list : lists) {
      if (list->empty()) continue;
      for (const PlotPoint& q : *list) {
        out << q.x << " " << q.y << " " << q.x_lo << " " << q.x_hi << " \"" << q.label << "\"\n";
      }
      out << "\n\n";
    }
  }
  return out.str();
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
std::string warm_line_style(std::size_t k) {
  const WarmStyle& w = kWarmStyles[k % (sizeof kWarmStyles / sizeof kWarmStyles[0])];
  return "lw 1.5 dt " + std::to_string(w.dash) + " pt " + std::to_string(w.point) +
         " ps 0.8 lc rgb '" + w.colour + "'";
}

// The rows of the key under the panels (the warm lines' entries take a third; four entries to a
// row at most) and its height (pixels).
int key_rows(const Diagram& d) {
  const int entries = 3 + static_cast<int>(d.warm_factors.size()) + d.any_diverged + d.show_floor +
                      d.any_clamped + d.any_never + d.any_unresolved + d.any_reference;
  return std::max(d.warm_factors.empty() ? 2 : 3, (entries + 3) / 4);
}
double key_height(const Diagram& d) { return 10.0 + 30.0 * key_rows(d); }

// The script's settings shared by every panel: log axes and their ranges, x tics at 1, 2 and 5
// per decade (the time axis spans one or two decades), margins, the title (height: the
// picture's, pixels) and the floor's line.
std::string script_head(const Diagram& d, const std::string& title, int height) {
  std::string xtics;
  for (double decade = std::pow(10.0, std::floor(std::log10(d.x_lo))); decade < d.x_hi; decade *= 10.0) {
    for (const double f : {1.0, 2.0, 5.0}) {
      if (f * decade >= d.x_lo && f * decade <= d.x_hi) {
        xtics += (xtics.empty() ? "" : ", ") + number(f * decade);
      }
    }
  }
  const double title_h = 40.0 / height;
  std::ostringstream gp;
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
  return gp.str();
}

// The plot of one panel from `data`, whose index blocks it reads from `index` on (advanced past
// its own). Its reference line, if any, with its label above or under it.
std::string panel_plot(const Panel& p, const Diagram& d, const fs::path& data, int& index) {
  std::ostringstream gp;
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
  // The lines with their error bars: the quartiles of each run's time (columns 3 and 4).
  block(p.iterations, "using 1:2:3:4 with xerrorlines lw 1.5 pt 7 ps 0.7 lc rgb '#1f77b4'");
  for (std::size_t k = 0; k < p.warm.size(); ++k) {
    block(p.warm[k], "using 1:2:3:4 with xerrorlines " + warm_line_style(k));
  }
  block(p.substeps, "using 1:2:3:4 with xerrorlines lw 1.5 dt 2 pt 5 ps 0.7 lc rgb '#e377c2'");
  block(p.paper, "using 1:2 with points pt 6 ps 2.2 lw 1.5 lc rgb 'black'");
  block(p.clamped, "using 1:2 with points pt 10 ps 1.6 lw 1.5 lc rgb 'black'");
  block(p.diverged, "using 1:2:3:4 with xerrorbars pt 2 ps 1.8 lw 2.5 lc rgb '#d62728'");
  block(p.unresolved, "using 1:2 with points pt 8 ps 2.2 lw 1.5 lc rgb '#b8860b'");
  block(p.never, "using 1:2:3:4 with xerrorbars pt 3 ps 1.8 lw 2 lc rgb '#7f7f7f'");
  block(p.labels_it, "using 1:2:5 with labels font ',8' tc rgb '#1f77b4'");
  block(p.labels_ss, "using 1:2:5 with labels font ',8' tc rgb '#c0399c'");
  block(p.labels_div, "using 1:2:5 with labels font ',8' tc rgb '#d62728'");
  block(p.labels_never, "using 1:2:5 with labels font ',8' tc rgb '#7f7f7f'");
  if (parts.empty()) {  // no run of this panel has the measure (e.g. no LCP residual for xpbd)
    gp << "set label 3 'no run here has this measure' at graph 0.5, graph 0.5 center font ',9' "
          "tc rgb 'gray30'\nplot NaN notitle\nunset label 3\n";
    return gp.str();
  }
  gp << "plot ";
  for (std::size_t k = 0; k < parts.size(); ++k) gp << (k ? ", \\\n     " : "") << parts[k];
  gp << "\n";
  return gp.str();
}

// The key: a frameless plot of nothing under the panels (key_h: its height, a fraction of the
// picture's), an entry per line and mark the diagram has.
std::string script_key(const Diagram& d, const Measure& m, double key_h) {
  std::ostringstream gp;
  gp << "unset arrow\nunset label\nunset title\nunset xlabel\nunset ylabel\nunset logscale\n"
     << "unset border\nunset tics\nunset grid\nset origin 0, 0\nset size 1, " << key_h << "\n"
     << "set lmargin 0\nset rmargin 0\nset tmargin 0\nset bmargin 0\n"
     << "set xrange [0:1]\nset yrange [0:1]\n"
     << "set key center center horizontal maxrows " << key_rows(d)
     << " width 1 samplen 3 font ',9'\nplot "
     << "NaN with linespoints lw 1.5 pt 7 lc rgb '#1f77b4' title "
     << gp_text("iterations, 1 substep (dt " + d.dt1 + ")");
  for (std::size_t k = 0; k < d.warm_factors.size(); ++k) {
    gp << ", NaN with linespoints " << warm_line_style(k) << " title "
       << gp_text("iterations, warm start " + shortest_decimal(d.warm_factors[k]));
  }
  gp << ", NaN with linespoints lw 1.5 dt 2 pt 5 lc rgb '#e377c2' title "
     << gp_text("substeps per step of " + d.dt1 + ", 25 iterations")
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
  if (d.any_never) {
    gp << ", NaN with points pt 3 ps 1.5 lw 2 lc rgb '#7f7f7f' title "
          "'never recovered by the horizon (on the top edge)'";
  }
  if (d.any_unresolved) {
    gp << ", NaN with points pt 8 ps 2 lw 1.5 lc rgb '#b8860b' title "
          "'below the reference''s own error, or it unknown: not resolved'";
  }
  if (d.any_reference) {
    gp << ", NaN with lines dt 4 lw 1.2 lc rgb '#b8860b' title "
          "'reference''s own error (from its order over 3 substep counts)'";
  }
  gp << "\nunset multiplot\n";
  return gp.str();
}

// The gnuplot commands that draw the diagram from `data` (plot_data) into the current terminal
// (height: the picture's, pixels): a grid of panels (pgs left, jacobi right, a row per push and
// friction model) on shared axes, and a key below them.
std::string plot_script(const Diagram& d, const fs::path& data, const std::string& title,
                        const Measure& m, int height) {
  const int n = static_cast<int>(d.panels.size());
  const int cols = n > 1 ? 2 : 1;
  const int rows = (n + cols - 1) / cols;
  const double title_h = 40.0 / height, key_h = key_height(d) / height;
  const double panel_w = 1.0 / cols, panel_h = (1.0 - title_h - key_h) / rows;
  std::ostringstream gp;
  gp << script_head(d, title, height);
  int index = 0;
  for (int i = 0; i < n; ++i) {
    const int col = i % cols, row = i / cols;
    gp << "set origin " << col * panel_w << ", " << key_h + (rows - 1 - row) * panel_h << "\n"
       << "set size " << panel_w << ", " << panel_h << "\n"
       << "set title " << gp_text(d.panels[static_cast<std::size_t>(i)].title)
       << " font ',10' offset 0,-0.4\n"
       << (row == rows - 1 ? "set xlabel 'physics CPU time per simulated second (s/s; "
                             "bars: quartiles of the repeats)' "
                             "font ',9' offset 0,0.4\n"
                           : "unset xlabel\n")
       << (col == 0 ? "set ylabel " + gp_text(m.axis) + " font ',9' offset 1,0\n" : "unset ylabel\n")
       << panel_plot(d.panels[static_cast<std::size_t>(i)], d, data, index);
    if (i == 0) gp << "unset label 100\n";
  }
  gp << script_key(d, m, key_h);
  return gp.str();
}

}  // namespace

bool draw_diagram(const fs::path& dir, const std::string& scene, const Measure& m,
                  const std::vector<const RunResult*>& runs, const std::string& title_note) {
  const std::optional<Diagram> diagram = make_diagram(m, floor_of(m, scene), runs);
  if (!diagram) return false;
  const std::string stem = file_stem(scene) + "_" + m.column;
  const fs::path data = dir / "plots" / (stem + ".dat");
  write_text_atomic(data, plot_data(*diagram));
  const int rows_of_panels = (static_cast<int>(diagram->panels.size()) + 1) / 2;
  const int width = 1100,
            height = 40 + static_cast<int>(key_height(*diagram)) + 300 * rows_of_panels;
  const std::string body = plot_script(*diagram, data, scene + ": " + m.label + title_note, m, height);
  draw_png_svg_pdf(dir, stem, body, width, height);
  return true;
}

}  // namespace cps::cli
