// cps_engine_benchmark: microseconds per step of the cps scenes next to the same scenes in
// Bullet and ODE, all measured in this one process, one thread, by the method of `cps bench`
// (demos/cps/bench.cpp): the world is advanced 1 s untimed so contacts have formed, then stepped
// in 5 timed blocks, each timed by the CPU time of this thread (so other processes on a shared
// machine do not count); the median block counts. Each cell is repeated (--repeats) with a fresh
// world, the engines interleaved, and the median over repeats is printed with the range.
// Each engine's final state is checked (the stack still stands, ...) so no exploded scene is
// timed unnoticed.
#include "engines.h"
#include "scene.h"

#include "cps/step_system.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace cps::compare {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

/// CPU time of the calling thread (s), the clock of `cps bench`.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// us/step of `step` (dt in s): 1 s untimed (the same loop as World::time() < 1), then 5 timed
/// blocks of `steps` by thread CPU time; the median block. `mark`, when given, is called once
/// between the untimed second and the first timed block.
double us_per_step(const std::function<void()>& step, double dt, int steps,
                   const std::function<void()>& mark = {}) {
  for (long k = 0; static_cast<double>(k) * dt < 1.0; ++k) step();
  if (mark) mark();
  std::vector<double> blocks;
  for (int b = 0; b < 5; ++b) {
    const double start = thread_cpu_seconds();
    for (int k = 0; k < steps; ++k) step();
    blocks.push_back(1e6 * (thread_cpu_seconds() - start) / steps);
  }
  return median(blocks);
}

/// The longest chain of dependent row updates in `sweeps` sweeps of projected Gauss-Seidel
/// (Sec. 7.2) on the system s (rows). Row j's update reads the latest lambda of every row i with
/// A_ji != 0 (they share a movable body; through w in the matrix-free solve): rows i < j of
/// this sweep, rows i >= j of the previous one. depth(j, k) = 1 + the largest depth of those, and
/// the chain is the largest depth after the last sweep: the updates no processor can overlap,
/// however many it could run at once. A chain of sweeps x rows means every update waits on the
/// one before it.
long dependent_chain(const StepSystem& s, int sweeps) {
  const auto c = static_cast<std::size_t>(s.rows());
  std::vector<long> previous(c, 0);
  std::vector<long> now(c, 0);
  for (int k = 0; k < sweeps; ++k) {
    for (std::size_t j = 0; j < c; ++j) {
      long deepest = previous[j];
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(s.A, static_cast<Eigen::Index>(j)); it; ++it) {
        if (it.value() == 0.0) continue;
        const auto i = static_cast<std::size_t>(it.col());
        deepest = std::max(deepest, i < j ? now[i] : previous[i]);
      }
      now[j] = deepest + 1;
    }
    previous.swap(now);
  }
  return c == 0 ? 0 : *std::max_element(previous.begin(), previous.end());
}

/// What --chain prints for one scene: mean rows and dependent chain per step over the timed
/// steps (dependent_chain over each step's solves), and us/step of cps matrix-free at 25 and at
/// 50 sweeps.
struct ChainRow {
  double rows = 0.0;       ///< rows per step, all solves (count)
  double chain = 0.0;      ///< dependent updates per step at 25 sweeps (count)
  double chain_one = 0.0;  ///< the same at 1 sweep (count)
  double us_50 = 0.0;      ///< us/step at 50 sweeps
  double us_25 = 0.0;      ///< us/step at 25 sweeps
};

/// Measures a ChainRow for `scene` by the method of us_per_step (1 s untimed at the scene's
/// settings, then 5 blocks of `steps`, median), the sweeps set after that first second. The
/// rows and chains are counted in a third, untimed run of the same steps at 25 sweeps (the
/// observer does not change the physics, so it sees the steps the 25-sweep run timed).
ChainRow chain_row(const scenes::Scene& scene, int steps) {
  ChainRow out;
  for (const int sweeps : {50, 25, 0}) {
    scenes::Run run = scenes::make_run(scene);
    const double dt = run.world.def().dt;
    for (long k = 0; static_cast<double>(k) * dt < 1.0; ++k) run.world.step();
    WorldDef def = run.world.def();
    def.assembly = Assembly::matrix_free;
    def.iterations = sweeps == 0 ? 25 : sweeps;
    run.world.set_def(def);
    if (sweeps == 0) {
      run.world.set_solve_observer([&](const StepSystem& s) {
        out.rows += static_cast<double>(s.rows());
        out.chain += static_cast<double>(dependent_chain(s, 25));
        out.chain_one += static_cast<double>(dependent_chain(s, 1));
      });
      for (int k = 0; k < 5 * steps; ++k) run.world.step();
      out.rows /= 5.0 * steps;
      out.chain /= 5.0 * steps;
      out.chain_one /= 5.0 * steps;
      continue;
    }
    std::vector<double> blocks;
    for (int b = 0; b < 5; ++b) {
      const double start = thread_cpu_seconds();
      for (int k = 0; k < steps; ++k) run.world.step();
      blocks.push_back(1e6 * (thread_cpu_seconds() - start) / steps);
    }
    (sweeps == 50 ? out.us_50 : out.us_25) = median(blocks);
  }
  return out;
}

/// The scene family: the name without a trailing _N.
std::string family_of(const std::string& name) {
  const std::size_t cut = name.rfind('_');
  if (cut != std::string::npos && cut + 1 < name.size() &&
      std::all_of(name.begin() + static_cast<long>(cut) + 1, name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return name.substr(0, cut);
  }
  return name;
}

struct Check {
  bool ok = true;
  std::string text;
};

/// The sanity check of one engine's final states against the scene as built (`initial`: the
/// cps world before its first step, for shapes, planes and rods).
Check sanity(const std::string& name, const World& initial, const std::vector<BodyState>& s) {
  char buf[256];
  Check c;
  for (const BodyState& b : s) {
    if (!b.x.allFinite() || !b.v.allFinite()) return {false, "non-finite state"};
  }
  const auto& bodies = initial.bodies();
  const std::string family = family_of(name);
  if (family == "stack") {
    // Top cube within 5 cm of its rest height h (2n - 1), no cube off the axis by 0.5 m (the
    // scene's own slide-off threshold).
    int n = 0;
    double h = 0.0, top = -1e300, drift = 0.0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].is_static()) continue;
      ++n;
      h = bodies[i].shape.half_extents.y();
      top = std::max(top, s[i].x.y());
      drift = std::max(drift, std::hypot(s[i].x.x(), s[i].x.z()));
    }
    const double dy = top - h * (2 * n - 1);
    c.ok = std::abs(dy) < 0.05 && drift < 0.5;
    std::snprintf(buf, sizeof buf, "top cube %+.3f m from rest height, max drift %.3f m", dy, drift);
  } else if (family == "funnel") {
    // Deepest ball into a wall (m) and fastest ball (m/s); fails beyond 5 cm or if a ball left.
    double pen = 0.0, speed = 0.0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].is_static()) continue;
      speed = std::max(speed, s[i].v.norm());
      for (const Body& w : bodies) {
        if (!w.is_static() || w.shape.kind != ShapeKind::plane) continue;
        const Vec3 n = w.rotation() * w.shape.normal;
        const double gap = n.dot(s[i].x) - n.dot(w.x) - w.shape.offset - bodies[i].shape.radius;
        pen = std::max(pen, -gap);
      }
    }
    c.ok = pen < 0.05;
    std::snprintf(buf, sizeof buf, "deepest ball into a wall %.4f m, fastest ball %.3f m/s", pen, speed);
  } else if (family == "pendulum_grid" || family == "pendulum_wave") {
    double err = 0.0, rel = 0.0;
    for (const DistanceConstraint& d : initial.distances()) {
      const BodyState& a = s[static_cast<std::size_t>(d.body_a)];
      const double e = std::abs((d.local_b - (a.x + a.R * d.local_a)).norm() - d.length);
      err = std::max(err, e);
      rel = std::max(rel, e / d.length);
    }
    if (family == "pendulum_wave") {
      c.ok = rel < 0.01;
      std::snprintf(buf, sizeof buf, "max rod error %.2e of its length", rel);
    } else {
      // Shapes on top, as the scene's metric counts them: above the grid's mean height and
      // over its footprint |x|, |z| <= 2.5 m.
      const int grid = static_cast<int>(initial.distances().size());
      double mean_y = 0.0;
      for (const DistanceConstraint& d : initial.distances()) mean_y += s[static_cast<std::size_t>(d.body_a)].x.y();
      mean_y /= grid;
      int on_top = 0, shapes = 0;
      for (std::size_t i = static_cast<std::size_t>(grid) + 1; i < s.size(); ++i) {
        ++shapes;
        const Vec3& x = s[i].x;
        if (x.y() > mean_y && std::abs(x.x()) <= 2.5 && std::abs(x.z()) <= 2.5) ++on_top;
      }
      c.ok = err < 0.05;
      if (grid == 25) {
        std::snprintf(buf, sizeof buf, "max rod error %.4f m, %d of %d shapes on top", err, on_top, shapes);
      } else {  // scaled grids have another footprint: the rods only
        std::snprintf(buf, sizeof buf, "max rod error %.4f m", err);
      }
    }
  } else {
    double low = 1e300;
    for (const BodyState& b : s) {
      if (!b.is_static) low = std::min(low, b.x.y());
    }
    c.ok = low > -1.0;
    std::snprintf(buf, sizeof buf, "lowest body centre y = %.3f m", low);
  }
  c.text = buf;
  return c;
}

struct Column {
  std::string label;
  std::vector<double> us;
  Check check;
  int contacts = 0;  ///< contact points of the last step
  Engine::Work work; ///< per step over the first repeat's timed steps: rows, row updates (count)
};

/// An engine's work over the timed steps (from `before`, taken at the mark, to `after`), per step.
Engine::Work work_per_step(const Engine::Work& before, const Engine::Work& after, int steps) {
  return {(after.rows - before.rows) / steps, (after.row_updates - before.row_updates) / steps};
}

/// cps's work a step between two StepCounters of one run: rows built a step, each swept
/// `iterations` times by each of the step's solves (solves a step over the window: exact when
/// every step of the window has rows, as in every scene here once its first second is over).
Engine::Work cps_work_per_step(const StepCounters& before, const StepCounters& after, int iterations) {
  const auto steps = static_cast<double>(after.steps - before.steps);
  if (steps <= 0.0) return {};
  const double rows = static_cast<double>(after.rows - before.rows) / steps;
  const double solves = static_cast<double>(after.solves - before.solves) / steps;
  return {rows, rows * solves * iterations};
}

int run(int argc, char** argv) {
  CLI::App app{"cps_engine_benchmark: us/step of the cps scenes and of the same scenes in Bullet and ODE "
               "(one thread, same process; method of `cps bench`)"};
  std::vector<std::string> names{"stack", "funnel", "pendulum_grid", "pendulum_wave"};
  int repeats = 5;
  int steps = 36;  // as `cps bench`: 5 blocks of 36 steps, 3 s of a 60 Hz scene
  app.add_option("--scene", names,
                 "scenes to compare (names as `cps list`, scaled ones too: stack_40, funnel_100, "
                 "pendulum_wave_1000, ...)")
      ->capture_default_str();
  app.add_option("--repeats", repeats, "fresh-world measurements per cell; the median is printed")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--steps", steps, "steps per timed block (5 blocks, median)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  bool chain = false;
  app.add_flag("--chain", chain,
               "also print each scene's dependent chain of PGS row updates and the time a sweep costs");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  for (const std::string& n : names) {
    if (!scenes::find_scene(n)) {
      std::fprintf(stderr, "cps_engine_benchmark: unknown scene '%s': use a name from `cps list` or a "
                           "scaled scene such as stack_40, funnel_100\n", n.c_str());
      return 2;
    }
  }

  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  const std::string load_before = load_average();
  std::printf("# cps_engine_benchmark, %s\n\n", date);
  std::printf("Bullet %s (btScalar %s, btSequentialImpulseConstraintSolver), ODE %s (dReal %s, "
              "dWorldQuickStep), cps (this build). One thread each, %d solver iterations, each "
              "scene's own dt. Per cell: 1 s untimed, 5 blocks of %d steps timed by thread CPU time, median block; %d "
              "fresh-world repeat(s), engines interleaved: median (min-max) us/step.\n\n",
              bullet_version().c_str(), bullet_precision().c_str(), CPS_ODE_VERSION,
              ode_precision().c_str(), 25, steps, repeats);
  std::printf("| scene | dt (s) | bodies | rods | Bullet | ODE | cps matrix-free | cps explicit |\n"
              "|---|---|---|---|---|---|---|---|\n");
  std::string checks;
  std::string ratios;
  std::string work;
  for (const std::string& name : names) {
    const scenes::Scene& scene = *scenes::find_scene(name);
    const scenes::Run built = scenes::make_run(scene);
    const World& initial = built.world;
    const double dt = initial.def().dt;
    std::vector<Column> cols;
    for (const char* label : {"Bullet", "ODE", "cps matrix-free", "cps explicit"}) cols.push_back({label, {}, {}, 0, {}});
    std::fprintf(stderr, "cps_engine_benchmark: %s\n", name.c_str());
    for (int r = 0; r < repeats; ++r) {
      for (int e = 0; e < 2; ++e) {
        std::unique_ptr<Engine> engine = e == 0 ? make_bullet(initial) : make_ode(initial);
        Engine::Work before;
        cols[static_cast<std::size_t>(e)].us.push_back(
            us_per_step([&] { engine->step(); }, dt, steps, [&] { before = engine->work(); }));
        if (r == 0) {
          cols[static_cast<std::size_t>(e)].check = sanity(name, initial, engine->states());
          cols[static_cast<std::size_t>(e)].contacts = engine->contacts();
          cols[static_cast<std::size_t>(e)].work = work_per_step(before, engine->work(), 5 * steps);
        }
      }
      // cps: exactly as bench.cpp's us_per_step (make_run, assembly set on the def, world.step()).
      for (int e = 0; e < 2; ++e) {
        scenes::Run run = scenes::make_run(scene);
        WorldDef def = run.world.def();
        def.assembly = e == 0 ? Assembly::matrix_free : Assembly::explicit_matrices;
        run.world.set_def(def);
        StepCounters before;
        cols[static_cast<std::size_t>(2 + e)].us.push_back(
            us_per_step([&] { run.world.step(); }, dt, steps, [&] { before = run.world.counters(); }));
        if (r == 0) {
          cols[static_cast<std::size_t>(2 + e)].work =
              cps_work_per_step(before, run.world.counters(), run.world.def().iterations);
          cols[static_cast<std::size_t>(2 + e)].check = sanity(name, initial, cps_states(run.world));
          int n = 0;
          for (const Manifold& m : run.world.manifolds()) n += m.count;
          cols[static_cast<std::size_t>(2 + e)].contacts = n;
        }
      }
    }
    std::size_t dynamic = 0;
    for (const Body& b : initial.bodies()) dynamic += b.is_static() ? 0 : 1;
    std::printf("| %s | %.5g | %zu | %zu |", name.c_str(), dt, dynamic, initial.distances().size());
    for (const Column& c : cols) {
      std::printf(" %.1f (%.1f-%.1f) |", median(c.us), *std::min_element(c.us.begin(), c.us.end()),
                  *std::max_element(c.us.begin(), c.us.end()));
    }
    std::printf("\n");
    // Each engine's time over cps matrix-free's in the same repeat (so a load change between
    // repeats cancels), median over the repeats.
    ratios += "| " + name + " |";
    for (const std::size_t e : {std::size_t{0}, std::size_t{1}, std::size_t{3}}) {
      std::vector<double> q;
      for (std::size_t r = 0; r < cols[e].us.size(); ++r) q.push_back(cols[e].us[r] / cols[2].us[r]);
      char cell[32];
      std::snprintf(cell, sizeof cell, " %.2f |", median(q));
      ratios += cell;
    }
    ratios += "\n";
    // Work a step (first repeat) and the step's time over its row updates (median us/step).
    char w[512];
    const auto per_update = [](const Column& c) {
      return c.work.row_updates > 0.0 ? 1e3 * median(c.us) / c.work.row_updates : 0.0;
    };
    std::snprintf(w, sizeof w, "| %s | %.1f | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                  name.c_str(), cols[0].work.rows, cols[0].work.rows > 0 ? cols[0].work.row_updates / cols[0].work.rows : 0.0,
                  cols[1].work.rows, cols[2].work.rows, cols[0].work.row_updates / std::max(1.0, cols[2].work.row_updates),
                  cols[1].work.row_updates / std::max(1.0, cols[2].work.row_updates),
                  per_update(cols[0]), per_update(cols[1]), per_update(cols[2]));
    work += w;
    const double end_time = std::ceil(1.0 / dt - 1e-9) * dt + 3.0 * steps * dt;
    for (const Column& c : cols) {
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %s | t = %.2f s: %s | %d | %s |\n", name.c_str(),
                    c.label.c_str(), end_time, c.check.text.c_str(), c.contacts, c.check.ok ? "ok" : "FAILED");
      checks += line;
    }
  }
  std::printf("\n## Time over cps matrix-free's in the same repeat, median over the repeats\n\n"
              "| scene | Bullet | ODE | cps explicit |\n|---|---|---|---|\n%s",
              ratios.c_str());
  std::printf("\n## Solver work a step, and the step's time per row update\n\n"
              "Rows handed to each solver a step and row updates a step (rows times the sweeps run), mean over the "
              "first repeat's timed steps; Bullet stops sweeping when its residual reaches 0 (its split-impulse "
              "passes are not counted). ns per row update: the median us/step above (the whole step, collision "
              "included) over the row updates a step.\n\n"
              "| scene | Bullet rows | Bullet sweeps | ODE rows | cps rows | Bullet updates / cps | ODE updates / cps "
              "| Bullet ns per update | ODE ns per update | cps ns per update |\n|---|---|---|---|---|---|---|---|---|---|\n%s",
              work.c_str());
  std::printf("\n## Sanity at the end of the first repeat's last timed block\n\n"
              "| scene | engine | state | contact points (last step) | check |\n|---|---|---|---|---|\n%s",
              checks.c_str());
  if (chain) {
    std::printf("\n## The sequential sweep's dependent chain (cps matrix-free, PGS)\n\n"
                "rows: rows per step; chain: dependent row updates per step at 25 sweeps (and at 1), both the mean over the timed steps; "
                "a sweep: (us/step at 50 - us/step at 25) / 25 (the same rows, nearly: the scenes rest); ns per row: a "
                "sweep's time over the rows; ns per chained update: a sweep's time over the chain a sweep adds, (chain at 25 - chain at 1) / 24. "
                "Median of %d repeat(s).\n\n"
                "| scene | rows | chain at 25 (at 1) | chain / (25 rows) | us/step at 25 | us/step at 50 | a sweep (us) | ns per row | ns per chained update |\n"
                "|---|---|---|---|---|---|---|---|---|\n", repeats);
    for (const std::string& name : names) {
      std::vector<ChainRow> rs;
      for (int r = 0; r < repeats; ++r) rs.push_back(chain_row(*scenes::find_scene(name), steps));
      const auto med = [&](auto field) {
        std::vector<double> v;
        for (const ChainRow& c : rs) v.push_back(field(c));
        return median(v);
      };
      const ChainRow& c = rs.front();
      const double sweep = med([](const ChainRow& x) { return (x.us_50 - x.us_25) / 25.0; });
      const double per_row = c.rows > 0 ? 1e3 * sweep / c.rows : 0.0;
      const double per_chained = c.chain > c.chain_one ? 1e3 * 24.0 * sweep / (c.chain - c.chain_one) : 0.0;
      std::printf("| %s | %.1f | %.1f (%.1f) | %.2f | %.1f | %.1f | %.2f | %.1f | %.1f |\n", name.c_str(),
                  c.rows, c.chain, c.chain_one, c.rows > 0 ? c.chain / (25.0 * c.rows) : 0.0,
                  med([](const ChainRow& x) { return x.us_25; }), med([](const ChainRow& x) { return x.us_50; }),
                  sweep, per_row, per_chained);
    }
  }
  std::printf("\nLoad average (1, 5, 15 min) before: %s, after: %s (2 cores, shared).\n",
              load_before.c_str(), load_average().c_str());
  return checks.find("FAILED") == std::string::npos ? 0 : 1;
}

}  // namespace

std::vector<BodyState> cps_states(const World& world) {
  std::vector<BodyState> out;
  for (const Body& b : world.bodies()) out.push_back({b.is_static(), b.x, b.rotation(), b.velocity()});
  return out;
}

}  // namespace cps::compare

int main(int argc, char** argv) {
  try {
    return cps::compare::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cps_engine_benchmark: %s\n", e.what());
    return 1;
  }
}
