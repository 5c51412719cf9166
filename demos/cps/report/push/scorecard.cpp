#include "report/push/scorecard.h"

#include "exact_lcp.h"
#include "report/run.h"
#include "stress/mass_ratio.h"
#include "stress/stress.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace cps::cli {
namespace {

// A number in a cell or sentence: 3 significant digits.
std::string score_brief(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

const scenes::Scene& score_scene(const char* name) {
  const scenes::Scene* s = scenes::find_scene(name);
  if (!s) throw std::logic_error(std::string("report push scorecard: no scene ") + name);
  return *s;
}

// m: how far a body may move from where it was built before it has left its place: half the
// cubes' edge (its centre over the edge of the cube under it), a link's radius for the rope (as
// the scene heavy_rope).
double score_leave_m(ScoreCase c) {
  return c == ScoreCase::rope ? scenes::kHeavyRopeLinkRadiusM : scenes::kMassRatioHalfEdge;
}

void score_populate(World& world, ScoreCase c, double ratio) {
  switch (c) {
    case ScoreCase::two_box: scenes::populate_mass_ratio_stack(world, ratio, 2); return;
    case ScoreCase::four_box: scenes::populate_mass_ratio_stack(world, ratio, 4); return;
    case ScoreCase::rope: scenes::populate_heavy_rope_ratio(world, ratio); return;
  }
}

// m: the constraint error now: the deepest overlap beyond the world's penetration slop, or the
// largest rod error, whichever is larger.
double score_error(const World& world) {
  const double overlap = scenes::max_penetration_now(world) - world.def().penetration_slop;
  return std::max({0.0, overlap, scenes::max_rod_error(world)});
}

// m: the largest distance of a movable body's centre from its place.
double score_displacement(const World& world, const std::vector<Vec3>& places) {
  double d = 0.0;
  for (std::size_t i = 0; i < places.size(); ++i) {
    const Body& b = world.body(static_cast<int>(i));
    if (!b.is_static()) d = std::max(d, (b.x - places[i]).norm());
  }
  return d;
}

}  // namespace

const char* score_case_name(ScoreCase c) {
  switch (c) {
    case ScoreCase::two_box: return "2-box";
    case ScoreCase::four_box: return "4-box";
    case ScoreCase::rope: return "rope";
  }
  return "?";
}

std::string ScoreRow::variant() const {
  if (exact) return "exact solve";
  if (k_start) return "avbd_k_start=" + number(*k_start);
  return "";
}

WorldDef score_world(ScoreCase c, const ScoreRow& row) {
  WorldDef def = c == ScoreCase::rope ? scenes::heavy_rope_world_def() : scenes::mass_ratio_world_def();
  const auto push = static_cast<PushMode>(row.method.value);
  def.push = push;
  if (row.settings == ScoreSettings::source) {
    const double friction = def.friction;
    switch (push) {
      case PushMode::baumgarte:  // the paper's own settings
      case PushMode::split:
        break;
      case PushMode::split_impulse:  // Bullet 2.x, btContactSolverInfo's defaults
        def.iterations = 10;
        def.warm_start = 0.85;
        def.split_impulse_threshold = 0.04;
        def.friction_model = FrictionModel::coupled;
        break;
      case PushMode::soft:  // Box3D's world, as its benchmark scenes run it
        def = score_scene("large_pyramid").world_def();
        break;
      case PushMode::ngs:  // Box2D v2.4: 8 velocity and 3 position iterations, b2_linearSlop
        def.iterations = 8;
        def.position_iterations = 3;
        def.warm_start = 1.0;
        def.penetration_slop = 0.005;
        def.max_correction = 0.2;
        def.friction_model = FrictionModel::coupled;
        break;
      case PushMode::tgs:  // PhysX 5 eTGS: 4 position iterations, contact offset 0.02 m
        def.iterations = 4;
        def.tgs_substeps = 4;
        def.contact_margin = 0.02;
        def.friction_model = FrictionModel::coupled;
        break;
      case PushMode::xpbd:  // Mueller et al. 2020: substeps of one iteration (cps's default 20)
        break;
      case PushMode::avbd:  // the AVBD authors' 3D demo
        def = score_scene("avbd_stack").world_def();
        break;
    }
    def.push = push;
    def.friction = friction;  // a property of the bodies' surfaces, not of the method
  }
  if (row.k_start) def.avbd_k_start = *row.k_start;
  if (row.exact) def.iterations = 1;  // the sweeps are replaced by the exact solve
  return def;
}

std::string score_source(const Method& m) {
  switch (static_cast<PushMode>(m.value)) {
    case PushMode::baumgarte:
      return "the paper's (Sec. 5.3, 10): the paper's settings";
    case PushMode::split:
      return "the paper's (Sec. 8.1): the paper's settings";
    case PushMode::split_impulse:
      return "Bullet 2.x's btContactSolverInfo: 10 iterations, warm starting 0.85, split impulse "
             "past 0.04 m of overlap, friction mu lambda_n (cps's one beta, 0.2, is Bullet's erp "
             "of the shallow contacts; its erp2 0.8 of the deep ones is not set)";
    case PushMode::soft:
      return "Box3D's world (the scene large_pyramid's): 4 substeps of one soft sweep and one relax "
             "sweep, warm starting, contact hertz 30, damping ratio 10, push speed cap 3 m/s, "
             "speculative margin 0.02 m, 4-point manifolds, contact recycling, friction mu lambda_n";
    case PushMode::ngs:
      return "Box2D v2.4's: 8 velocity and 3 position iterations, warm starting, linear slop "
             "0.005 m, max correction 0.2 m, friction mu lambda_n";
    case PushMode::tgs:
      return "PhysX 5's eTGS: 4 position iterations as 4 substeps of one sweep, contact offset "
             "0.02 m, friction mu lambda_n (cps's relax gets the same 4 sweeps where PhysX's "
             "default is 1 velocity iteration)";
    case PushMode::xpbd:
      return "Mueller et al. 2020's: substeps of one iteration, 20 a step (the same as the paper's "
             "settings: xpbd reads no iteration count)";
    case PushMode::avbd:
      return "the AVBD authors' 3D demo (the scene avbd_stack's world): 10 iterations, beta 1e4, "
             "alpha 0.99, gamma 0.999, penalties 1 to 1e10 N/m, no post-stabilisation, contacts "
             "resting 0.01 m deep";
  }
  return "";
}

ScoreCell run_score_cell(ScoreCase c, double ratio, const ScoreRow& row) {
  ScoreCell cell;
  cell.ratio = ratio;
  World world(score_world(c, row));
  score_populate(world, c, ratio);
  std::string refused;
  if (row.exact) {
    world.set_solve_override([&](const StepSystem& s, Eigen::VectorXd& lambda) {
      if (!refused.empty()) return;
      try {
        lambda = analysis::solve_exact(s, kScoreExactTolerance).lambda;
      } catch (const std::exception& e) {
        refused = "the exact solve refused step " + std::to_string(s.step) + " (t = " +
                  score_brief(static_cast<double>(s.step) * s.dt) + " s): " + e.what();
      }
    });
  }
  const std::vector<Vec3> places = scenes::resting_places_as_built(world);
  const double leave_m = score_leave_m(c);
  double out_since = -1.0;  // s: the start of the current time out of place; < 0: in place
  const double dt = world.def().dt;
  const double end_from = kScoreSeconds - scenes::HardCaseWatch::kHoldS;  // s
  double error = 0.0, speed = 0.0;
  while (scenes::short_of(world, kScoreSeconds)) {
    world.step();
    cell.seconds = world.time();
    if (!refused.empty()) {
      cell.why = refused;
      return cell;  // held stays nullopt: the exact row was not run
    }
    if (!sane_state(world)) {
      cell.held = false;
      cell.why = "diverged at " + score_brief(world.time()) + " s";
      return cell;
    }
    if (score_displacement(world, places) <= leave_m) {
      out_since = -1.0;
    } else if (out_since < 0.0) {
      out_since = world.time();
    } else if (world.time() - out_since + 0.5 * dt >= scenes::HardCaseWatch::kHoldS) {
      cell.held = false;
      cell.why = "left at " + score_brief(out_since) + " s";
      return cell;
    }
    if (world.time() + 0.5 * dt > end_from) {
      error = std::max(error, score_error(world));
      speed = std::max(speed, largest_speed(world));
    }
  }
  cell.end_error_m = error;
  cell.end_speed_mps = speed;
  if (out_since >= 0.0) {
    cell.held = false;
    cell.why = "not in place at the end";
  } else if (error > kScoreErrorM) {
    cell.held = false;
    cell.why = "error " + score_brief(error) + " m";
  } else if (speed > kScoreSpeedMps) {
    cell.held = false;
    cell.why = "speed " + score_brief(speed) + " m/s";
  } else {
    cell.held = true;
  }
  return cell;
}

std::vector<ScoreRow> score_rows(const std::vector<Method>& methods) {
  std::vector<ScoreRow> rows;
  std::optional<Method> avbd, baumgarte;
  for (const Method& m : methods) {
    for (const ScoreSettings s : {ScoreSettings::paper, ScoreSettings::source}) {
      rows.push_back({.method = m, .settings = s, .k_start = std::nullopt, .exact = false});
    }
    if (m.name == kTunedMethod) avbd = m;
    if (static_cast<PushMode>(m.value) == PushMode::baumgarte) baumgarte = m;
  }
  if (avbd) {
    for (const ScoreSettings s : {ScoreSettings::paper, ScoreSettings::source}) {
      rows.push_back({.method = *avbd, .settings = s, .k_start = kTunedAvbdKStart, .exact = false});
    }
  }
  if (baumgarte) rows.push_back({.method = *baumgarte, .settings = ScoreSettings::paper, .k_start = std::nullopt, .exact = true});
  return rows;
}

std::vector<ScoreResult> run_scorecard(const std::vector<ScoreRow>& rows,
                                       const std::function<void()>& tick) {
  std::vector<ScoreResult> results;
  results.reserve(rows.size());
  for (const ScoreRow& row : rows) {
    ScoreResult r{.row = row, .cells = {}};
    for (std::size_t k = 0; k < kScoreCases.size(); ++k) {
      for (int p = 1; p <= kScoreRatioPowers; ++p) {
        r.cells[k].push_back(run_score_cell(kScoreCases[k], std::ldexp(1.0, p), row));
        tick();
      }
    }
    results.push_back(std::move(r));
  }
  return results;
}

double held_up_to(const std::vector<ScoreCell>& cells) {
  double up_to = 0.0;
  for (const ScoreCell& c : cells) {
    if (!c.held || !*c.held) break;
    up_to = c.ratio;
  }
  return up_to;
}

CsvTable score_table(const std::vector<ScoreResult>& results) {
  CsvTable t;
  t.columns = {"settings", "push", "variant", "case", "mass_ratio", "held", "why",
               "end_error_m", "end_speed_mps", "seconds_s", "dt_s", "iterations"};
  for (const ScoreResult& r : results) {
    for (std::size_t k = 0; k < kScoreCases.size(); ++k) {
      const WorldDef def = score_world(kScoreCases[k], r.row);
      for (const ScoreCell& c : r.cells[k]) {
        t.rows.push_back({r.row.settings == ScoreSettings::paper ? "paper" : "source",
                          r.row.method.name, r.row.variant(), score_case_name(kScoreCases[k]),
                          number(c.ratio), c.held ? (*c.held ? "1" : "0") : "", c.why,
                          number(c.end_error_m), number(c.end_speed_mps), number(c.seconds),
                          number(def.dt), std::to_string(def.iterations)});
      }
    }
  }
  return t;
}

namespace {

// A row's name in push.md's tables.
std::string score_row_name(const ScoreRow& row) {
  if (row.exact) return "exact solve (Siconos), push factor";
  std::string name = row.method.name;
  if (row.k_start) name += ", tuned (`--avbd-k-start " + score_brief(*row.k_start) + "`)";
  return name;
}

const char* score_settings_name(ScoreSettings s) { return s == ScoreSettings::paper ? "paper" : "source"; }

// The largest ratio held from 2 up ("none"), ", then not run" when the next was not run, and the
// largest ratio held where it is larger.
std::string score_up_to_cell(const std::vector<ScoreCell>& cells) {
  const double up_to = held_up_to(cells);
  std::string text = up_to == 0.0 ? "none" : number(up_to);
  double largest = 0.0;
  for (const ScoreCell& c : cells) {
    if (c.held && *c.held) largest = c.ratio;
  }
  for (const ScoreCell& c : cells) {
    if (c.ratio > up_to) {
      if (!c.held) text += ", then not run";
      break;
    }
  }
  if (largest > up_to) text += " (" + number(largest) + " held)";
  return text;
}

}  // namespace

std::string score_markdown(const std::vector<ScoreResult>& results,
                           const std::vector<Method>& methods) {
  std::ostringstream md;
  md << "## Mass ratio scorecard\n\n"
     << "Each case is built at rest on its supports, touching, and run " << number(kScoreSeconds)
     << " s at each ratio R = 2, 4, ..., 2^" << kScoreRatioPowers << ":\n\n"
     << "- **2-box**: a cube of R kg on a cube of 1 kg on the ground (edge 1 m);\n"
     << "- **4-box**: four cubes of edge 1 m from 1 kg at the bottom to R kg on top, each R^(1/3) "
        "times the one below;\n"
     << "- **rope**: a cube of R x 0.1 kg hanging on " << scenes::kHeavyRopeLinks << " rods of "
     << number(scenes::kHeavyRopeRodLengthM) << " m and balls of 0.1 kg from a fixed point (the "
        "scene heavy_rope's rope).\n\n"
     << "A case **holds** at R when the state stays sane, no body leaves its place (its centre "
        "farther than half the cube edge, or a link's radius for the rope, from where it was "
        "built, for " << number(scenes::HardCaseWatch::kHoldS) << " s), and over the last "
     << number(scenes::HardCaseWatch::kHoldS) << " s no overlap is deeper than the method's "
        "penetration slop by more than " << number(kScoreErrorM * 1e3) << " mm, no rod is off "
        "its length by more than " << number(kScoreErrorM * 1e3) << " mm and no body's centre is "
        "faster than " << number(kScoreSpeedMps * 1e3) << " mm/s. **held up to** is the largest R "
        "such that every ratio from 2 to R held, with the largest ratio held in brackets where it is "
        "larger. Settings: **paper**, the paper's (dt 1/60 s, 25 "
        "PGS sweeps, beta 0.2, mu 0.5) with only the push changed; **source**, the method's own "
        "source's defaults at the same dt and mu:\n\n";
  for (const Method& m : methods) md << "- " << m.name << ": " << score_source(m) << ".\n";
  md << "\nThe **exact solve** row is the paper's push at the paper's settings with every step's "
        "A lambda = b solved exactly (Siconos numerics' Lemke, polished, or where its active set "
        "cycles the polish from PGS sweeps or from proximal point iterates; "
        "World::set_solve_override; each solve's natural-map residual under "
     << number(kScoreExactTolerance) << " of its force scale) in place of the 25 sweeps: what "
        "is left of a failure there is the step's (the time step, the push factor, the paper's "
        "friction bound mu m |g.n|), not the sweeps'. A blank cell: the exact solve refused a "
        "step of that run (score.csv says which). Every cell: score.csv (why a run failed, its end "
        "error and speed).\n\n"
     << "| push | settings | 2-box held up to | 4-box held up to | rope held up to |\n"
     << "|---|---|---|---|---|\n";
  for (const ScoreResult& r : results) {
    md << "| " << score_row_name(r.row) << " | " << score_settings_name(r.row.settings);
    for (const auto& cells : r.cells) md << " | " << score_up_to_cell(cells);
    md << " |\n";
  }
  for (std::size_t k = 0; k < kScoreCases.size(); ++k) {
    md << "\n**" << score_case_name(kScoreCases[k]) << "** (x: held, .: not held, "
       << "blank: not run), by log2 R:\n\n| push | settings |";
    for (int p = 1; p <= kScoreRatioPowers; ++p) md << " " << p << " |";
    md << "\n|---|---|";
    for (int p = 1; p <= kScoreRatioPowers; ++p) md << "---|";
    md << "\n";
    for (const ScoreResult& r : results) {
      md << "| " << score_row_name(r.row) << " | " << score_settings_name(r.row.settings) << " |";
      for (const ScoreCell& c : r.cells[k]) md << " " << (c.held ? (*c.held ? "x" : ".") : "") << " |";
      md << "\n";
    }
  }
  return md.str();
}

}  // namespace cps::cli
